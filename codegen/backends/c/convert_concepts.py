"""The ops between a format's field and the shared concepts as C (the strict policy's two halves),
as ``codegen/backends/python/converters/{numeric,choices,cells}.py`` write them in Python: reading
(forward) a field's value becomes the concept's unit unless it is an unknown marker; writing
(backward) unknown becomes the marker, a value is stored as the field holds it, and what is
clamped, rounded, written as a marker or has no counterpart is reported.

The concepts are :data:`STATE` (``battgen_concepts``): per concept ``has_<name>`` (Python's
``None``) and its value -- a double for numbers, int64_t for integers, a code for a choice
(``BATTGEN_<CONCEPT>_<CHOICE>``, 0 none), a bit per choice for flags, doubles for a list; a text
concept holds only whether it is known (no C converter writes text yet)."""

from __future__ import annotations

import math

from ...ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Concept,
    Field,
    FieldRef,
    PrimitiveKind,
    PrimitiveType,
    Rule,
    Unit,
    units,
)
from ...ir import ops as o
from ...ir.fieldtypes import allowed_range
from ...ir.mapping_values import Number
from .convert_context import CBase
from .convert_values import Unsupported, f64_literal, literal
from .types import ident, scalar

STATE = "battgen_concepts"
LIST_MAX = 255  # the elements a list concept holds (DroneCAN's voltage_cell: up to 255)
_MARKED = "a known value written as the unknown marker"


def _double(value: float | int) -> str:
    return f64_literal(float(value))


def _factor(frm: Unit | None, to: Unit | None) -> tuple[float, float]:
    return (1.0, 0.0) if frm is None or to is None else frm.factor_to(to)


def _affine(expr: str, mul: float, add: float) -> str:
    """Python's ``affine``: ``expr * mul + add``, each step in double as Python computes it."""
    out = expr
    if mul != 1.0:
        out = f"{out} * {_double(mul)}"
    if add != 0.0:
        out = f"{out} + {_double(add)}"
    return out


def _nan(value: object) -> bool:
    return isinstance(value, float) and math.isnan(value)


def choice_name(concept: str, choice: str) -> str:
    return f"BATTGEN_{ident(concept).upper()}_{ident(choice).upper()}"


def state_lines(concepts: dict[str, Concept]) -> list[str]:
    """``#define``s of the choices and flags, then the ``battgen_concepts`` struct."""
    defines: list[str] = []
    members: list[str] = []
    for c in concepts.values():
        name = ident(c.name)
        unit = f" /* [{c.unit.symbol}] */" if c.unit is not None else ""
        members.append(f"bool has_{name};")
        if c.kind == "number":
            members.append(f"double {name};{unit}")
        elif c.kind == "integer":
            members.append(f"int64_t {name};")
        elif c.kind == "bool":
            members.append(f"bool {name};")
        elif c.kind == "choice":
            defines += [f"#define {choice_name(c.name, x)} {i + 1}u" for i, x in enumerate(c.choices)]
            members.append(f"uint8_t {name}; /* {choice_name(c.name, '*')}, 0: none */")
        elif c.kind == "flags":
            if len(c.choices) > 32:
                raise Unsupported(f"{c.name}: more than 32 flags")
            defines += [f"#define {choice_name(c.name, x)} (1uL << {i}u)" for i, x in enumerate(c.choices)]
            members.append(f"uint32_t {name}; /* {choice_name(c.name, '*')} bits */")
        elif c.kind == "list":
            members += [f"uint16_t {name}_len;", f"double {name}[{LIST_MAX}];{unit}"]
    return [
        *defines,
        "",
        "/* The shared battery state (schemas/mappings/concepts.yaml): has_<name> false is unknown. */",
        "typedef struct {",
        *members,
        f"}} {STATE};",
    ]


class ConceptOps(CBase):
    concepts: dict[str, Concept]

    def format_and_concept(self, rule: Rule) -> tuple[FieldRef, FieldRef]:
        fmt, con = rule.sources[0], rule.targets[0]
        if fmt.message == CONCEPTS_ENDPOINT:
            fmt, con = con, fmt
        if self.backward:
            self.read.add((CONCEPTS_ENDPOINT, con.field))
        return fmt, con

    def markers(self, f: Field, unknown: tuple[Number, ...]) -> list[float | int]:
        out: list[float | int] = []
        for m in ([f.invalid.value] if f.invalid is not None else []) + list(unknown):
            if not any((_nan(m) and _nan(x)) or m == x for x in out):
                out.append(m)
        return out

    def read_value(self, fmt: FieldRef, expr: str | None = None) -> tuple[str, str]:
        """(C type, expression) of a field's value as Python holds it: a double for floats, else int64_t."""
        p = self.prim(fmt)
        value = expr or self.s(fmt)
        if p.kind is PrimitiveKind.FLOAT:
            return "double", f"(double){value}"
        return "int64_t", f"(int64_t){value}"

    def known_tests(self, var: str, ctype: str, marks: list[float | int]) -> list[str]:
        out = []
        for m in marks:
            if _nan(m):
                if ctype == "double":
                    out.append(f"!battgen_f64_is_nan({var})")
            else:
                out.append(f"{var} != {_double(m) if ctype == 'double' else int(m)}")
        return out

    def concept(self, con: FieldRef) -> Concept:
        return self.concepts[con.field]

    def set_concept(self, con: FieldRef, value: str) -> list[str]:
        target = self.t(con)
        return [f"t->has_{ident(con.field)} = true;", f"{target} = {value};"]

    # -- values stored as the field holds them (backward) --------------------------------------

    def int_range(self, f: Field, p: PrimitiveType, hi: Number | None, marks: list[float | int]) -> tuple[int, int]:
        """Python's ``RuleContext.int_bounds``: the integers a converter may write into the field."""
        rng = allowed_range(p, f.range).intersect(self.rule_ranges.get(f))
        type_lo, type_hi = (int(v) for v in p.value_range or (0, 0))
        lo = (
            type_lo
            if rng.minimum is None
            else math.floor(rng.minimum) + 1
            if rng.exclusive_minimum
            else math.ceil(rng.minimum)
        )
        top = (
            type_hi
            if rng.maximum is None
            else math.ceil(rng.maximum) - 1
            if rng.exclusive_maximum
            else math.floor(rng.maximum)
        )
        if hi is not None:
            top = min(top, math.floor(hi))
        lo, top = max(lo, type_lo), min(top, type_hi)
        while lo < top and any(lo == m for m in marks if not _nan(m)):
            lo += 1
        while top > lo and any(top == m for m in marks if not _nan(m)):
            top -= 1
        return (lo, top) if lo <= top else (type_lo, type_hi)

    def store(self, fmt: FieldRef, expr: str, hi: Number | None = None, marks: tuple[Number, ...] = ()) -> str:
        """The double ``expr`` as the field holds it (Python's ``store``)."""
        f = self.fld(fmt)
        p = self.prim(fmt)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"battgen_f16_round((float)({expr}), rep, {self.label(fmt)})"
            return f"(float)({expr})" if p.bits == 32 else f"({expr})"
        if p.kind is PrimitiveKind.BOOL:
            return f"(({expr}) != 0)"
        lo, top = self.int_range(f, p, hi, self.markers(f, marks))
        c = scalar(p)
        return f"({c})battgen_to_int({expr}, {lo}LL, {top}LL, rep, {self.label(fmt)})"

    def marked(self, target: str, fmt: FieldRef, mark: float | int, label: str) -> str:
        """A known value written as the field's marker is reported clamped."""
        add = f"battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {label});"
        return f"if ({target} == {literal(self.prim(fmt), mark)}) {{ {add} }}"

    # -- the ops ---------------------------------------------------------------------------

    def concept_const(self, ref: FieldRef, value: object) -> None:
        """A constant into a concept (forward; the concepts are written, not read, backward)."""
        if self.backward:
            return
        kind = self.concept(ref).kind
        if kind == "choice" and isinstance(value, str):
            text = choice_name(ref.field, value)
        elif kind == "bool":
            text = "true" if value else "false"
        elif kind == "number" and isinstance(value, int | float):
            text = _double(value)
        elif kind == "integer" and isinstance(value, int):
            text = f"{value}LL"
        else:
            raise Unsupported(f"the constant {value!r} into {ref.field}")
        self.emit(*self.set_concept(ref, text))

    def visit_scale(self, rule: Rule, op: o.Scale) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        if isinstance(f.type, ArrayType):
            raise Unsupported("a devicetree list")
        marks = self.markers(f, op.unknown)
        c_unit = self.concept(con).unit
        f_unit = f.unit or (units.lookup(op.unit) if op.unit is not None else c_unit)
        negated = op.negate
        if not self.backward:
            mul, add = _factor(f_unit, c_unit)
            if negated:
                mul, add = -mul, -add
            ctype, value = self.read_value(fmt)
            self.emit(f"{ctype} v = {value};")
            tests = self.known_tests("v", ctype, marks)
            if op.valid_above is not None:
                tests.append(f"v > {_double(op.valid_above) if ctype == 'double' else op.valid_above}")
            if op.valid_max is not None:
                tests.append(f"v <= {_double(op.valid_max) if ctype == 'double' else op.valid_max}")
            out = _affine("(double)v", mul, add) + (" + 0.0" if negated and add == 0.0 else "")
            body = self.set_concept(con, out)
            self.emit(*([f"if ({' && '.join(tests)}) {{", *body, "}"] if tests else body))
            return
        mul, add = _factor(c_unit, f_unit)
        if negated:
            mul = -mul
        target, label = self.t(fmt), self.label(fmt)
        name = ident(con.field)
        self.emit(f"if (!s->has_{name} || battgen_f64_is_nan(s->{name})) {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});", "} else {")
        value = _affine(f"s->{name}", mul, add) + (" + 0.0" if negated and add == 0.0 else "")
        self.emit(f"{target} = {self.store(fmt, value, op.valid_max, op.unknown)};")
        for m in (m for m in marks if not _nan(m)):
            self.emit(self.marked(target, fmt, m, label))
        self.emit("}")

    def visit_copy(self, rule: Rule, op: o.Copy) -> None:
        fmt, con = self.format_and_concept(rule)
        f = self.fld(fmt)
        add = op.add or 0
        marks = self.markers(f, op.unknown)
        kind = self.concept(con).kind
        name = ident(con.field)
        if not self.backward:
            if kind == "text":
                t = f.type
                src = self.s(fmt)
                # Python's text_in: bytes up to the first NUL, empty is unknown
                known = (f"{src}_len > 0u && " if isinstance(t, ArrayType) and t.dynamic else "") + f"{src}[0] != 0"
                self.emit(f"t->has_{name} = {known};")
                self.written.add((CONCEPTS_ENDPOINT, con.field))
                return
            ctype, read = self.read_value(fmt)
            self.emit(f"{ctype} v = {read};")
            if kind == "bool":
                value = "v != 0"
            elif kind == "integer":
                if ctype == "double":
                    raise Unsupported("a float copied into an integer concept")
                value = f"v + {int(add)}" if add else "v"
            else:
                value = f"(double)v + {_double(add)}" if add else "(double)v"
            tests = self.known_tests("v", ctype, marks)
            body = self.set_concept(con, value)
            self.emit(*([f"if ({' && '.join(tests)}) {{", *body, "}"] if tests else body))
            return
        if kind == "text":
            raise Unsupported("text written to a field")
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"if (!s->has_{name}) {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});", "} else {")
        value = f"(double)s->{name}" + (f" - {_double(add)}" if add else "")
        if kind == "bool":
            value = f"(s->{name} ? 1.0 : 0.0)"
        self.emit(f"{target} = {self.store(fmt, value, None, op.unknown)};")
        if kind != "bool":
            for m in (m for m in marks if not _nan(m)):
                self.emit(self.marked(target, fmt, m, label))
        self.emit("}")

    def visit_soc_hybrid(self, rule: Rule, op: o.SocHybrid) -> None:
        if self.backward:
            raise Unsupported("soc_hybrid backward")
        remaining, full = rule.sources[:2]
        con = rule.targets[0]
        self.emit(
            f"double e = (double){self.s(remaining)};",
            f"double f = (double){self.s(full)};",
            "if (!battgen_f64_is_nan(e) && !battgen_f64_is_nan(f) && e > 0.0 && f > 0.0) {",
            "double q = e / f;",
            *self.set_concept(con, "1.0 < q ? 1.0 : q"),
        )
        if len(rule.sources) < 3:
            self.emit("}")
            return
        percent = rule.sources[2]
        f = self.fld(percent)
        mul, add = _factor(f.unit, self.concept(con).unit)
        ctype, read = self.read_value(percent)
        tests = self.known_tests("p", ctype, self.markers(f, op.unknown))
        if op.valid_max is not None:
            tests.append(f"p <= {_double(op.valid_max) if ctype == 'double' else op.valid_max}")
        self.emit(
            "} else {",
            f"{ctype} p = {read};",
            f"if ({' && '.join(tests) or '1'}) {{",
            *self.set_concept(con, _affine("(double)p", mul, add)),
            "}",
            "}",
        )

    def note_bits(self, fmt: FieldRef, mask: int) -> None:
        self.bit_masks[fmt.message, fmt.field] = self.bit_masks.get((fmt.message, fmt.field), 0) | mask

    def visit_flag(self, rule: Rule, op: o.Flag) -> None:
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        if self.backward:
            self.emit(f"if (s->has_{ident(con.field)} && s->{ident(con.field)}) {{ {self.t(fmt)} |= {mask}u; }}")
            return
        self.note_bits(fmt, mask)
        self.emit(*self.set_concept(con, f"((uint64_t){self.s(fmt)} & {mask}uLL) != 0u"))

    def visit_flag_choice(self, rule: Rule, op: o.FlagChoice) -> None:
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        code = choice_name(con.field, op.value)
        if self.backward:
            name = ident(con.field)
            self.emit(f"if (s->has_{name} && s->{name} == {code}) {{ {self.t(fmt)} |= {mask}u; }}")
            return
        self.note_bits(fmt, mask)
        self.emit(f"if (((uint64_t){self.s(fmt)} & {mask}uLL) != 0u) {{", *self.set_concept(con, code), "}")

    def visit_flags(self, rule: Rule, op: o.Flags) -> None:
        fmt, con = self.format_and_concept(rule)
        concept = self.concept(con)
        table = {bit.choice: self.mask(bit.mask, [fmt]) for bit in op.map}
        ordered = [(c, table[c]) for c in concept.choices if c in table]
        name = ident(con.field)
        if not self.backward:
            self.note_bits(fmt, sum(table.values()))
            self.emit(f"uint64_t v = (uint64_t){self.s(fmt)};", "uint32_t b = 0u;")
            for choice, mask in ordered:
                self.emit(f"if ((v & {mask}uLL) != 0u) {{ b |= {choice_name(con.field, choice)}; }}")
            self.emit(*self.set_concept(con, "b"))
            return
        target, label = self.t(fmt), self.label(fmt)
        p = self.prim(fmt)
        others = " | ".join(choice_name(con.field, c) for c in concept.choices if c not in table) or "0u"
        self.emit(
            f"if (!s->has_{name}) {{",
            f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});",
            "} else {",
            f"uint64_t b = (uint64_t){target};",
        )
        for choice, mask in ordered:
            self.emit(f"if ((s->{name} & {choice_name(con.field, choice)}) != 0u) {{ b |= {mask}uLL; }}")
        self.emit(
            f"{target} = ({scalar(p)})b;",
            f"if ((s->{name} & ({others})) != 0u) {{",
            f'battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, "concepts.{con.field}");',
            "}",
            "}",
        )

    def visit_choice(self, rule: Rule, op: o.Choice) -> None:
        fmt, con = self.format_and_concept(rule)
        table = [(entry.choice, self.value_of(entry.value, [fmt])) for entry in op.map]
        unknown = self.value_of(op.unknown, [fmt]) if op.unknown is not None else None
        p = self.prim(fmt)
        name = ident(con.field)
        if not self.backward:
            ctype, read = self.read_value(fmt)
            if ctype != "int64_t":
                raise Unsupported("a choice read from a float")
            by_value: dict[object, str] = {}
            for choice, value in table:
                by_value[value] = choice  # the last wins, as Python's dict
            self.emit(f"int64_t v = {read};", f"t->has_{name} = true;", "switch (v) {")
            for value, choice in by_value.items():
                self.emit(f"case {int(value)}LL:", f"{self.t(con)} = {choice_name(con.field, choice)};", "break;")  # type: ignore[call-overload]
            skip = "" if unknown is None else f" && v != {int(unknown)}LL"  # type: ignore[call-overload]
            self.emit(
                "default:",
                f"t->has_{name} = false;",
                f"if (1{skip}) {{ battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, {self.label(fmt)}); }}",
                "break;",
                "}",
            )
            return
        target, label = self.t(fmt), self.label(fmt)
        by_choice: dict[str, object] = {}
        for choice, value in table:
            by_choice[choice] = value
        self.emit("bool w = false;", f"if (s->has_{name}) {{", f"switch (s->{name}) {{")
        for choice, value in by_choice.items():
            self.emit(
                f"case {choice_name(con.field, choice)}:", f"{target} = {literal(p, value)};", "w = true;", "break;"
            )
        self.emit("default:", "break;", "}", "}", "if (!w) {")
        if unknown is not None:
            self.emit(f"{target} = {literal(p, unknown)};")
        self.emit(
            f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});",
            f'if (s->has_{name}) {{ battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, "concepts.{con.field}"); }}',
            "}",
        )

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
            if _nan(mark):
                return f"battgen_f64_is_nan((double){x})" if el.kind is PrimitiveKind.FLOAT else "false"
            return f"{x} == {literal(el, mark)}"

        if not self.backward:
            mul, add = _factor(f_unit, c_unit)
            src = self.s(fmt)
            n = f"{src}_len" if t.dynamic else f"{cap}u"
            self.emit("size_t i, n;", f"n = (size_t){n};")
            if f.invalid is not None and f.invalid.first_decides:
                first = f.invalid.value
                test = f"battgen_f64_is_nan((double){src}[0])" if _nan(first) else f"{src}[0] == {literal(el, first)}"
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
            value = _affine(f"(double){src}[i]", mul, add)
            if mark is not None:
                value = f"{is_mark(src + '[i]')} ? {_double(math.nan)} : {value}"
            self.emit(
                f"if (n > {LIST_MAX}u) {{ n = {LIST_MAX}u; }}",
                f"t->has_{name} = n > 0u;",
                f"t->{name}_len = (uint16_t)n;",
                f"for (i = 0; i < n; i++) {{ t->{name}[i] = {value}; }}",
            )
            self.written.add((CONCEPTS_ENDPOINT, con.field))
            return
        mul, add = _factor(c_unit, f_unit)
        target, label = self.t(fmt), self.label(fmt)
        if t.dynamic:
            raise Unsupported("cells into a dynamic array")
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
        stored = self.store(fmt, _affine("x", mul, add))
        stored = stored.replace(f"{self.label(fmt)})", f"{label})")
        if mark is not None:
            self.emit(f"{target}[i] = battgen_f64_is_nan(x) ? {literal(el, mark)} : {stored};")
        else:
            self.emit(f"{target}[i] = {stored};")
        fill = literal(el, mark) if mark is not None else literal(el, 0)
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
            mul, add = _factor(main_f.unit, v_unit)
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
                f"t->{pn} = {_affine('(double)sum', mul, add)};",
                f"if (n > 1u && got[0] != {mm - 1}) {{",
                f"t->has_{cn} = true;",
                f"t->{cn}_len = (uint16_t)n;",
                f"for (k = 0; k < n; k++) {{ t->{cn}[k] = {_affine('(double)got[k]', mul, add)}; }}",
                "}",
                "}",
            )
            return
        mul, add = _factor(v_unit, main_f.unit)
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
            f"double c = {_affine(f's->{cn}[i]', mul, add)};",
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
            f"int64_t mv = battgen_to_int({_affine(f's->{pn}', mul, add)}, 0, {top * n_main}, rep, {lm});",
            "i = 0;",
            f"while (mv > {top} && i < {n_main - 1}u) {{ {main}[i] = {top}u; mv -= {top}; i++; }}",
            f"{main}[i] = ({c_main})mv;",
            "} else {",
            f"battgen_loss_add(rep, BATTGEN_LOSS_UNKNOWN, {lm});",
            "}",
        )
