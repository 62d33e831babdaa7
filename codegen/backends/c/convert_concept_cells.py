"""The cell-array ops between a format and the concepts as C (``cells``, MAVLink's
``mavlink_voltages``), as ``codegen/backends/python/converters/cells.py`` and the run-time
``_cells.py`` compute them."""

from __future__ import annotations

import math

from ...ir import CONCEPTS_ENDPOINT, ArrayType, FieldRef, PrimitiveKind, PrimitiveType, Rule
from ...ir import ops as o
from .convert_concepts import LIST_MAX, ConceptOps, affine, double_literal, is_nan_value, unit_factor
from .convert_values import Unsupported, literal
from .types import ident, scalar


class ConceptCellOps(ConceptOps):
    def visit_cells(self, rule: Rule, op: o.Cells) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        t = f.type
        if not isinstance(t, ArrayType) or not isinstance(t.element, PrimitiveType):
            raise Unsupported("cells of a non-array")
        cap = t.capacity or 0
        mark = f.invalid.value if f.invalid is not None and f.invalid.per_element else None
        c_unit = self.concept(con).unit
        f_unit = f.unit or c_unit
        count_ref = FieldRef(fmt.message, op.count_field) if op.count_field else None
        name = ident(con.field)
        el = t.element

        def is_mark(x: str) -> str:
            assert mark is not None
            if is_nan_value(mark):
                return f"battgen_f64_is_nan((double){x})" if el.kind is PrimitiveKind.FLOAT else "false"
            return f"{x} == {literal(el, mark)}"

        if not self.backward:
            mul, add = unit_factor(f_unit, c_unit)
            src = self.s(fmt)
            n = f"{src}_len" if t.dynamic else f"{cap}u"
            self.emit("size_t i, n;", f"n = (size_t){n};")
            if f.invalid is not None and f.invalid.first_decides:
                first = f.invalid.value
                test = (
                    f"battgen_f64_is_nan((double){src}[0])"
                    if is_nan_value(first)
                    else f"{src}[0] == {literal(el, first)}"
                )
                self.emit(f"if (n > 0u && {test}) {{ n = 0u; }}")
            leading = (
                ["for (i = 0; i < n; i++) {", f"if ({is_mark(src + '[i]')}) {{ break; }}", "}", "n = i;"]
                if mark is not None
                else []
            )
            if count_ref is not None:
                count = self.s(count_ref)
                self.emit(
                    f"if ({count} != 0) {{",
                    f"if ((size_t){count} < n) {{ n = (size_t){count}; }}",
                    "} else {",
                    *leading,
                    "}",
                )
            else:
                self.emit(*leading)
            value = affine(f"(double){src}[i]", mul, add)
            if mark is not None:
                value = f"{is_mark(src + '[i]')} ? {double_literal(math.nan)} : {value}"
            self.emit(
                f"if (n > {LIST_MAX}u) {{ n = {LIST_MAX}u; }}",
                f"t->has_{name} = n > 0u;",
                f"t->{name}_len = (uint16_t)n;",
                f"for (i = 0; i < n; i++) {{ t->{name}[i] = {value}; }}",
            )
            self.written.add((CONCEPTS_ENDPOINT, con.field))
            return
        mul, add = unit_factor(c_unit, f_unit)
        target, label = self.t(fmt), self.label(fmt)
        self.emit(
            "size_t i, n;",
            f"if (!s->has_{name}) {{",
            f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});",
            "} else {",
            f"n = (size_t)s->{name}_len;",
            f"if (n > {cap}u) {{ battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {label}); n = {cap}u; }}",
            "for (i = 0; i < n; i++) {",
            f"double x = s->{name}[i];",
        )
        stored = self.store(fmt, affine("x", mul, add))
        stored = stored.replace(f"{self.label(fmt)})", f"{label})")
        if mark is not None:
            self.emit(f"{target}[i] = battgen_f64_is_nan(x) ? {literal(el, mark)} : {stored};")
        else:
            self.emit(f"{target}[i] = {stored};")
        fill = literal(el, mark) if mark is not None else literal(el, 0)
        if t.dynamic:
            self.emit("}", f"{target}_len = (uint16_t)n;")
        else:
            self.emit("}", f"for (i = n; i < {cap}u; i++) {{ {target}[i] = {fill}; }}")
        if count_ref is not None:
            count = self.t(count_ref)
            self.emit(
                f"if ({count} == 0) {{",
                f"{count} = ({scalar(self.prim(count_ref))})n;",
                f"battgen_loss_discard(rep_u, BATTGEN_LOSS_UNKNOWN, {self.label(count_ref)});",
                "}",
            )
        self.emit("}")

    def visit_mavlink_voltages(self, rule: Rule, op: o.MavlinkVoltages) -> None:
        """BATTERY_STATUS voltages (+ voltages_ext) <-> pack voltage and cells, as the run-time
        ``mavlink_cells_in`` / ``mavlink_cells_out`` do."""
        main_ref, ext_ref = rule.sources
        pack, cells = rule.targets
        main_f, ext_f = self.fld(main_ref), self.fld(ext_ref)
        n_main = main_f.type.capacity if isinstance(main_f.type, ArrayType) else None
        n_ext = ext_f.type.capacity if isinstance(ext_f.type, ArrayType) else None
        if not n_main or not n_ext:
            raise Unsupported("MAVLink voltages of unknown size")
        mm = int(main_f.invalid.value) if main_f.invalid is not None else 0xFFFF
        em = int(ext_f.invalid.value) if ext_f.invalid is not None else 0
        v_unit = self.concept(pack).unit
        pn, cn = ident(pack.field), ident(cells.field)
        if not self.backward:
            mul, add = unit_factor(main_f.unit, v_unit)
            main, ext = self.s(main_ref), self.s(ext_ref)
            self.written |= {(CONCEPTS_ENDPOINT, pack.field), (CONCEPTS_ENDPOINT, cells.field)}
            self.emit(
                f"int64_t got[{n_main + n_ext}], sum = 0;",
                "size_t n = 0, k;",
                f"while (n < {n_main}u && {main}[n] != {mm}u) {{ got[n] = (int64_t){main}[n]; n++; }}",
                f"if (n == {n_main}u) {{",
                f"for (k = 0; k < {n_ext}u && {ext}[k] != {em}u; k++) {{ got[n++] = (int64_t){ext}[k]; }}",
                "}",
                "for (k = 0; k < n; k++) { sum += got[k]; }",
                "if (n > 0u) {",
                f"t->has_{pn} = true;",
                f"t->{pn} = {affine('(double)sum', mul, add)};",
                f"if (n > 1u && got[0] != {mm - 1}) {{",
                f"t->has_{cn} = true;",
                f"t->{cn}_len = (uint16_t)n;",
                f"for (k = 0; k < n; k++) {{ t->{cn}[k] = {affine('(double)got[k]', mul, add)}; }}",
                "}",
                "}",
            )
            return
        mul, add = unit_factor(v_unit, main_f.unit)
        top = mm - 1
        main, ext = self.t(main_ref), self.t(ext_ref)
        lm, le = self.label(main_ref), self.label(ext_ref)
        self.read |= {(CONCEPTS_ENDPOINT, pack.field), (CONCEPTS_ENDPOINT, cells.field)}
        c_main, c_ext = scalar(self.prim(main_ref)), scalar(self.prim(ext_ref))
        self.emit(
            "size_t i, n = 0;",
            "bool any = false;",
            f"for (i = 0; i < {n_main}u; i++) {{ {main}[i] = {mm}u; }}",
            f"for (i = 0; i < {n_ext}u; i++) {{ {ext}[i] = {em}u; }}",
            f"if (s->has_{cn}) {{",
            f"n = (size_t)s->{cn}_len;",
            f"for (i = 0; i < n; i++) {{ if (!battgen_f64_is_nan(s->{cn}[i])) {{ any = true; }} }}",
            "}",
            "if (n > 0u && any) {",
            f"if (n > {n_main + n_ext}u) {{",
            f"battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {le});",
            f"n = {n_main + n_ext}u;",
            "}",
            "for (i = 0; i < n; i++) {",
            f"double c = {affine(f's->{cn}[i]', mul, add)};",
            f"if (i < {n_main}u) {{",
            "if (battgen_f64_is_nan(c)) {",
            f"{main}[i] = {mm}u;",
            f"battgen_loss_add(rep, BATTGEN_LOSS_UNREPRESENTABLE, {lm});",
            "} else {",
            f"{main}[i] = ({c_main})battgen_to_int(c, 0, {top}, rep, {lm});",
            "}",
            "} else if (battgen_f64_is_nan(c)) {",
            f"{ext}[i - {n_main}u] = {em}u;",
            f"battgen_loss_add(rep, BATTGEN_LOSS_UNREPRESENTABLE, {le});",
            "} else {",
            f"int64_t v = battgen_to_int(c, 0, {top}, rep, {le});",
            f"{ext}[i - {n_main}u] = ({c_ext})(v < {1 if em == 0 else 0} ? {1 if em == 0 else 0} : v);",
            "}",
            "}",
            f"}} else if (s->has_{pn} && !battgen_f64_is_nan(s->{pn})) {{",
            f"int64_t mv = battgen_to_int({affine(f's->{pn}', mul, add)}, 0, {top * n_main}, rep, {lm});",
            "i = 0;",
            f"while (mv > {top} && i < {n_main - 1}u) {{ {main}[i] = {top}u; mv -= {top}; i++; }}",
            f"{main}[i] = ({c_main})mv;",
            "} else {",
            f"battgen_loss_add(rep, BATTGEN_LOSS_UNKNOWN, {lm});",
            "}",
        )
