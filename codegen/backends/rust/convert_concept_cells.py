"""The cell-array ops between a format and the concepts as Rust (``cells``, MAVLink's
``mavlink_voltages``; the C backend's ``convert_concept_cells``, in Rust), as the Python
backend's ``cells.py`` and the run-time ``_cells.py`` compute them."""

from __future__ import annotations

import math

from ...ir import CONCEPTS_ENDPOINT, ArrayType, FieldRef, PrimitiveKind, PrimitiveType, Rule
from ...ir import ops as o
from .convert_concepts import LIST_MAX, ConceptOps, affine, double_literal, is_nan_value, unit_factor
from .convert_context import cast, paren
from .convert_values import Unsupported, literal
from .types import capacity, scalar


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
        name = self.cname(con)
        el = t.element
        rust = scalar(el)
        if el.kind is PrimitiveKind.BOOL:
            raise Unsupported("cells of bools")

        def as_f64(x: str) -> str:
            return cast(x, rust, "f64") if rust in ("f64", "i64", "u64") else f"f64::from({x})"

        def is_mark(x: str) -> str:
            assert mark is not None
            if is_nan_value(mark):
                return f"{x}.is_nan()" if el.kind is PrimitiveKind.FLOAT else "false"
            return f"{x} == {literal(el, mark)}"

        if not self.backward:
            mul, add = unit_factor(f_unit, c_unit)
            src = self.s(fmt)
            n = f"{src}_len.min({capacity(t)})" if t.dynamic else f"{cap}"
            self.emit(f"let mut n: usize = {n};")
            if f.invalid is not None and f.invalid.first_decides:
                first = f.invalid.value
                test = f"{src}[0].is_nan()" if is_nan_value(first) else f"{src}[0] == {literal(el, first)}"
                if is_nan_value(first) and el.kind is not PrimitiveKind.FLOAT:
                    test = "false"
                self.emit(f"if n > 0 && {test} {{ n = 0; }}")
            leading = (
                [
                    "let mut i = 0;",
                    "while i < n {",
                    f"if {is_mark(src + '[i]')} {{ break; }}",
                    "i += 1;",
                    "}",
                    "n = i;",
                ]
                if mark is not None
                else []
            )
            if count_ref is not None:
                count = self.s(count_ref)
                crust = self.rust(count_ref)
                as_usize = cast(count, crust, "usize")
                if leading:
                    self.emit(
                        f"if {count} != 0 {{",
                        f"if {paren(as_usize)} < n {{ n = {as_usize}; }}",
                        "} else {",
                        *leading,
                        "}",
                    )
                else:
                    self.emit(f"if {count} != 0 && {paren(as_usize)} < n {{ n = {as_usize}; }}")
            else:
                self.emit(*leading)
            value = affine(as_f64(f"{src}[i]"), mul, add)
            if mark is not None:
                value = f"if {is_mark(src + '[i]')} {{ {double_literal(math.nan)} }} else {{ {value} }}"
            self.emit(
                f"n = n.min({LIST_MAX});",
                f"t.has_{name} = n > 0;",
                f"t.{name}_len = n;",
                f"for i in 0..n {{ t.{name}[i] = {value}; }}",
            )
            self.written.add((CONCEPTS_ENDPOINT, con.field))
            return
        mul, add = unit_factor(c_unit, f_unit)
        target, label = self.t(fmt), self.label(fmt)
        self.emit(
            f"if !s.has_{name} {{",
            f"r.add_u(LossKind::Unknown, {label});",
            "} else {",
            f"let mut n = s.{name}_len;",
            f"if n > {cap} {{ r.add(LossKind::Clamped, {label}); n = {cap}; }}",
            "for i in 0..n {",
            f"let x = s.{name}[i];",
        )
        stored = self.store(fmt, affine("x", mul, add))
        if mark is not None:
            self.emit(f"{target}[i] = if x.is_nan() {{ {literal(el, mark)} }} else {{ {stored} }};")
        else:
            self.emit(f"{target}[i] = {stored};")
        fill = literal(el, mark) if mark is not None else literal(el, 0)
        if t.dynamic:
            self.emit("}", f"{target}_len = n;")
        else:
            self.emit("}", f"for i in n..{cap} {{ {target}[i] = {fill}; }}")
        if count_ref is not None:
            count = self.t(count_ref)
            self.emit(
                f"if {count} == 0 {{",
                f"{count} = {cast('n', 'usize', self.rust(count_ref))};",
                f"r.discard_u(LossKind::Unknown, {self.label(count_ref)});",
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
        pn, cn = self.cname(pack), self.cname(cells)
        r_main, r_ext = self.rust(main_ref), self.rust(ext_ref)
        if not self.backward:
            mul, add = unit_factor(main_f.unit, v_unit)
            main, ext = self.s(main_ref), self.s(ext_ref)
            self.written |= {(CONCEPTS_ENDPOINT, pack.field), (CONCEPTS_ENDPOINT, cells.field)}
            self.emit(
                f"let mut got = [0_i64; {n_main + n_ext}];",
                "let mut n = 0;",
                f"while n < {n_main} && {main}[n] != {mm} {{ got[n] = {self.as_i64(f'{main}[n]', r_main)}; n += 1; }}",
                f"if n == {n_main} {{",
                "let mut k = 0;",
                f"while k < {n_ext} && {ext}[k] != {em} {{",
                f"got[n] = {self.as_i64(f'{ext}[k]', r_ext)};",
                "n += 1;",
                "k += 1;",
                "}",
                "}",
                "let sum: i64 = got[..n].iter().sum();",
                "if n > 0 {",
                f"t.has_{pn} = true;",
                f"t.{pn} = {affine('(sum as f64)', mul, add)};",
                f"if n > 1 && got[0] != {mm - 1} {{",
                f"t.has_{cn} = true;",
                f"t.{cn}_len = n;",
                f"for (c, g) in t.{cn}.iter_mut().zip(&got[..n]) {{ *c = {affine('(*g as f64)', mul, add)}; }}",
                "}",
                "}",
            )
            return
        mul, add = unit_factor(v_unit, main_f.unit)
        top = mm - 1
        main, ext = self.t(main_ref), self.t(ext_ref)
        lm, le = self.label(main_ref), self.label(ext_ref)
        self.read |= {(CONCEPTS_ENDPOINT, pack.field), (CONCEPTS_ENDPOINT, cells.field)}
        low = 1 if em == 0 else 0
        self.emit(
            "let mut n = 0;",
            f"{main} = [{mm}; {n_main}];",
            f"{ext} = [{em}; {n_ext}];",
            f"if s.has_{cn} {{ n = s.{cn}_len; }}",
            f"let any = s.{cn}[..n].iter().any(|c| !c.is_nan());",
            "if n > 0 && any {",
            f"if n > {n_main + n_ext} {{",
            f"r.add(LossKind::Clamped, {le});",
            f"n = {n_main + n_ext};",
            "}",
            "for i in 0..n {",
            f"let c = {affine(f's.{cn}[i]', mul, add)};",
            f"if i < {n_main} {{",
            "if c.is_nan() {",
            f"{main}[i] = {mm};",
            f"r.add(LossKind::Unrepresentable, {lm});",
            "} else {",
            f"{main}[i] = {cast(f'r.round_int(c, 0, {top}, {lm})', 'i64', r_main)};",
            "}",
            "} else if c.is_nan() {",
            f"{ext}[i - {n_main}] = {em};",
            f"r.add(LossKind::Unrepresentable, {le});",
            "} else {",
            f"let v = r.round_int(c, 0, {top}, {le});",
            f"{ext}[i - {n_main}] = {cast(f'(if v < {low} {{ {low} }} else {{ v }})', 'i64', r_ext)};",
            "}",
            "}",
            f"}} else if s.has_{pn} && !s.{pn}.is_nan() {{",
            f"let mut mv = r.round_int({affine(f's.{pn}', mul, add)}, 0, {top * n_main}, {lm});",
            "let mut i = 0;",
            f"while mv > {top} && i < {n_main - 1} {{ {main}[i] = {top}; mv -= {top}; i += 1; }}",
            f"{main}[i] = {cast('mv', 'i64', r_main)};",
            "} else {",
            f"r.add(LossKind::Unknown, {lm});",
            "}",
        )
