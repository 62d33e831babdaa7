"""The ops between a format's field and the shared concepts as C (the strict policy's two halves),
as ``codegen/backends/python/converters/{numeric,choices,cells}.py`` write them in Python: reading
(forward) a field's value becomes the concept's unit unless it is an unknown marker; writing
(backward) unknown becomes the marker, a value is stored as the field holds it, and what is
clamped, rounded, written as a marker or has no counterpart is reported.

The concepts are :data:`STATE` (``battgen_concepts``): per concept ``has_<name>`` (Python's
``None``) and its value -- a double for numbers, int64_t for integers, a code for a choice
(``BATTGEN_<CONCEPT>_<CHOICE>``, 0 none), a bit per choice for flags, doubles for a list, UTF-8
bytes for a text (bytes read from a byte array decoded as Python decodes them, invalid sequences
as U+FFFD; a MAVLink string's chars as they are)."""

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
    StringType,
    Unit,
    units,
)
from ...ir import ops as o
from ...ir.fieldtypes import allowed_range, writable_ints
from ...ir.mapping_values import Number
from .convert_context import CBase
from .convert_values import Unsupported, f64_literal, literal
from .types import ident, scalar

STATE = "battgen_concepts"
LIST_MAX = 255  # the elements a list concept holds (DroneCAN's voltage_cell: up to 255)
TEXT_MAX = 3 * 256  # the UTF-8 bytes a text concept holds (255 bytes, each possibly U+FFFD)
_MARKED = "a known value written as the unknown marker"


def double_literal(value: float | int) -> str:
    return f64_literal(float(value))


def unit_factor(frm: Unit | None, to: Unit | None) -> tuple[float, float]:
    return (1.0, 0.0) if frm is None or to is None else frm.factor_to(to)


def affine(expr: str, mul: float, add: float) -> str:
    """``expr * mul + add`` in the order Python evaluates it, each step in double as Python computes it."""
    out = f"{expr} * {double_literal(mul)}" if mul != 1.0 else expr
    return f"{out} + {double_literal(add)}" if add != 0.0 else out


def is_nan_value(value: object) -> bool:
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
        elif c.kind == "text":
            members += [f"uint16_t {name}_len;", f"uint8_t {name}[{TEXT_MAX}]; /* UTF-8 */"]
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
            if not any((is_nan_value(m) and is_nan_value(x)) or m == x for x in out):
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
            if is_nan_value(m):
                if ctype == "double":
                    out.append(f"!battgen_f64_is_nan({var})")
            else:
                out.append(f"{var} != {double_literal(m) if ctype == 'double' else int(m)}")
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
        return writable_ints(p, rng, hi, marks)

    def store(self, fmt: FieldRef, expr: str, hi: Number | None = None, marks: tuple[Number, ...] = ()) -> str:
        """The double ``expr`` as the field holds it (Python's ``store``)."""
        f = self.fld(fmt)
        p = self.prim(fmt)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"battgen_f16_round_d({expr}, rep, {self.label(fmt)})"
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
            text = double_literal(value)
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
            mul, add = unit_factor(f_unit, c_unit)
            if negated:
                mul, add = -mul, -add
            ctype, value = self.read_value(fmt)
            self.emit(f"{ctype} v = {value};")
            tests = self.known_tests("v", ctype, marks)
            if op.valid_above is not None:
                tests.append(f"v > {double_literal(op.valid_above) if ctype == 'double' else op.valid_above}")
            if op.valid_max is not None:
                tests.append(f"v <= {double_literal(op.valid_max) if ctype == 'double' else op.valid_max}")
            out = affine("(double)v", mul, add) + (" + 0.0" if negated and add == 0.0 else "")
            body = self.set_concept(con, out)
            self.emit(*([f"if ({' && '.join(tests)}) {{", *body, "}"] if tests else body))
            return
        mul, add = unit_factor(c_unit, f_unit)
        if negated:
            mul = -mul
        target, label = self.t(fmt), self.label(fmt)
        name = ident(con.field)
        self.emit(f"if (!s->has_{name} || battgen_f64_is_nan(s->{name})) {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});", "} else {")
        value = affine(f"s->{name}", mul, add) + (" + 0.0" if negated and add == 0.0 else "")
        self.emit(f"{target} = {self.store(fmt, value, op.valid_max, op.unknown)};")
        for m in (m for m in marks if not is_nan_value(m)):
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
                self.text_in(fmt, con)
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
                value = f"(double)v + {double_literal(add)}" if add else "(double)v"
            tests = self.known_tests("v", ctype, marks)
            body = self.set_concept(con, value)
            self.emit(*([f"if ({' && '.join(tests)}) {{", *body, "}"] if tests else body))
            return
        if kind == "text":
            self.text_out(fmt, con)
            return
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"if (!s->has_{name}) {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});", "} else {")
        value = f"(double)s->{name}" + (f" - {double_literal(add)}" if add else "")
        if kind == "bool":
            value = f"(s->{name} ? 1.0 : 0.0)"
        self.emit(f"{target} = {self.store(fmt, value, None, op.unknown)};")
        if kind != "bool":
            for m in (m for m in marks if not is_nan_value(m)):
                self.emit(self.marked(target, fmt, m, label))
        self.emit("}")

    def text_in(self, fmt: FieldRef, con: FieldRef) -> None:
        """Python's ``text_in``: a byte array up to its first NUL, decoded (invalid UTF-8 as U+FFFD); a
        MAVLink string's chars as they are; empty is unknown."""
        t = self.fld(fmt).type
        src, name = self.s(fmt), ident(con.field)
        self.written.add((CONCEPTS_ENDPOINT, con.field))
        if isinstance(t, StringType):
            cap = (t.capacity or 0) + 0
            self.emit(
                "size_t n = 0;",
                f"while (n < {cap}u && {src}[n] != 0) {{ t->{name}[n] = (uint8_t){src}[n]; n++; }}",
            )
        elif isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.element.bits == 8:
            count = f"(size_t){src}_len" if t.dynamic else f"{t.capacity or 0}u"
            self.emit(
                "size_t n = 0;",
                f"while (n < {count} && {src}[n] != 0u) {{ n++; }}",
                f"n = battgen_utf8_replace((const uint8_t *){src}, n, t->{name});",
            )
        else:
            raise Unsupported("text from a field that is not bytes")
        self.emit(f"t->{name}_len = (uint16_t)n;", f"t->has_{name} = n > 0u;")

    def text_out(self, fmt: FieldRef, con: FieldRef) -> None:
        """Unknown: the field's empty text; else a string gets the text, a byte array its UTF-8 bytes
        (Python's ``bytes_out``: beyond the capacity reported clamped and cut)."""
        f = self.fld(fmt)
        t = f.type
        target, label, name = self.t(fmt), self.label(fmt), ident(con.field)
        if not isinstance(t, StringType | ArrayType):
            raise Unsupported("text into a number")
        cap = t.capacity or 0
        dynamic = isinstance(t, ArrayType) and t.dynamic
        cast = "(char)" if isinstance(t, StringType) else ""
        clear = f"{target}_len = 0u;" if dynamic else f"battgen_zero({target}, sizeof {target});"
        self.emit(f"if (!s->has_{name}) {{")
        if f.invalid is not None or dynamic:
            self.emit(clear)
        self.emit(f"battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, {label});", "} else {", "size_t i;")
        self.emit(f"size_t n = (size_t)s->{name}_len;")
        self.emit(f"if (n > {cap}u) {{ battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {label}); n = {cap}u; }}")
        if not dynamic:
            self.emit(f"battgen_zero({target}, sizeof {target});")
        self.emit(f"for (i = 0; i < n; i++) {{ {target}[i] = {cast}s->{name}[i]; }}")
        if dynamic:
            self.emit(f"{target}_len = (uint16_t)n;")
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
        mul, add = unit_factor(f.unit, self.concept(con).unit)
        ctype, read = self.read_value(percent)
        tests = self.known_tests("p", ctype, self.markers(f, op.unknown))
        if op.valid_max is not None:
            tests.append(f"p <= {double_literal(op.valid_max) if ctype == 'double' else op.valid_max}")
        self.emit(
            "} else {",
            f"{ctype} p = {read};",
            f"if ({' && '.join(tests) or '1'}) {{",
            *self.set_concept(con, affine("(double)p", mul, add)),
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
