"""The ops between a format's field and the shared concepts as Rust (the strict policy's two
halves; the C backend's ``convert_concepts``, in Rust), as the Python backend's converters write
them: reading (forward) a field's value becomes the concept's unit unless it is an unknown marker;
writing (backward) unknown becomes the marker, a value is stored as the field holds it, and what
is clamped, rounded, written as a marker or has no counterpart is reported.

The concepts are :data:`STATE` (``Concepts``, private to the module): per concept ``has_<name>``
(Python's ``None``) and its value -- an f64 for numbers, i64 for integers, a code for a choice
(``<CONCEPT>_<CHOICE>``, 0 none), a bit per choice for flags, f64s for a list, UTF-8 bytes for a
text (bytes read from a byte array decoded as Python decodes them, invalid sequences as U+FFFD)."""

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
from .convert_context import RustBase, cast, paren
from .convert_values import Unsupported, f64_literal, literal
from .naming import field_ident, upper
from .types import capacity, scalar

STATE = "Concepts"
LIST_MAX = 255  # the elements a list concept holds (DroneCAN's voltage_cell: up to 255)
TEXT_MAX = 3 * 256  # the UTF-8 bytes a text concept holds (255 bytes, each possibly U+FFFD)


def double_literal(value: float | int) -> str:
    return f64_literal(float(value))


def unit_factor(frm: Unit | None, to: Unit | None) -> tuple[float, float]:
    return (1.0, 0.0) if frm is None or to is None else frm.factor_to(to)


def affine(expr: str, mul: float, add: float) -> str:
    """``expr * mul + add`` in the order Python evaluates it, each step in f64 as Python computes it."""
    out = f"{expr} * {double_literal(mul)}" if mul != 1.0 else expr
    if mul == -1.0:  # the same bits as the product (clippy: neg_multiply)
        out = f"-{paren(expr)}"
    return f"{out} + {double_literal(add)}" if add != 0.0 else out


def is_nan_value(value: object) -> bool:
    return isinstance(value, float) and math.isnan(value)


def choice_name(concept: str, choice: str) -> str:
    return f"{upper(concept)}_{upper(choice)}"


def f64_of(expr: str, ctype: str) -> str:
    return cast(expr, ctype, "f64")


def state_lines(concepts: dict[str, Concept]) -> list[str]:
    """The choices' and flags' constants, then the ``Concepts`` struct and its empty value."""
    consts: list[str] = []
    members: list[tuple[str, str, str, str]] = []  # (name, type, zero, doc)
    for c in concepts.values():
        name = field_ident(c.name)
        unit = f" [{c.unit.symbol}]" if c.unit is not None else ""
        members.append((f"has_{name}", "bool", "false", f"`{c.name}` is known"))
        if c.kind == "number":
            members.append((name, "f64", "0.0", f"`{c.name}`{unit}"))
        elif c.kind == "integer":
            members.append((name, "i64", "0", f"`{c.name}`"))
        elif c.kind == "bool":
            members.append((name, "bool", "false", f"`{c.name}`"))
        elif c.kind == "choice":
            consts += [f"const {choice_name(c.name, x)}: u8 = {i + 1};" for i, x in enumerate(c.choices)]
            members.append((name, "u8", "0", f"`{c.name}`: one of its constants, 0 none"))
        elif c.kind == "flags":
            if len(c.choices) > 32:
                raise Unsupported(f"{c.name}: more than 32 flags")
            consts += [f"const {choice_name(c.name, x)}: u32 = 1 << {i};" for i, x in enumerate(c.choices)]
            members.append((name, "u32", "0", f"`{c.name}`: its constants' bits"))
        elif c.kind == "list":
            members.append((f"{name}_len", "usize", "0", f"the elements of `{c.name}` held"))
            members.append((name, f"[f64; {LIST_MAX}]", f"[0.0; {LIST_MAX}]", f"`{c.name}`{unit}"))
        elif c.kind == "text":
            members.append((f"{name}_len", "usize", "0", f"the bytes of `{c.name}` held"))
            members.append((name, f"[u8; {TEXT_MAX}]", f"[0; {TEXT_MAX}]", f"`{c.name}` (UTF-8)"))
    return [
        *consts,
        "",
        "/// The shared battery state (schemas/mappings/concepts.yaml): `has_<name>` false is unknown.",
        "#[allow(dead_code)] // every concept is held, whether some converter reads it back or not",
        f"struct {STATE} {{",
        *(f"/// {doc}\n{name}: {rust}," for name, rust, _, doc in members),
        "}",
        "",
        f"impl {STATE} {{",
        "const fn new() -> Self {",
        "Self {",
        *(f"{name}: {zero}," for name, _, zero, _ in members),
        "}",
        "}",
        "}",
    ]


class ConceptOps(RustBase):
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
        """(Rust type, expression) of a field's value as Python holds it: an f64 for floats, else i64."""
        p = self.prim(fmt)
        value = expr or self.s(fmt)
        if p.kind is PrimitiveKind.FLOAT:
            return "f64", cast(value, scalar(p), "f64") if p.bits > 32 else f"f64::from({value})"
        return "i64", self.as_i64(value, scalar(p))

    def known_tests(self, var: str, ctype: str, marks: list[float | int]) -> list[str]:
        out = []
        for m in marks:
            if is_nan_value(m):
                if ctype == "f64":
                    out.append(f"!{var}.is_nan()")
            else:
                out.append(f"{var} != {double_literal(m) if ctype == 'f64' else int(m)}")
        return out

    def bound(self, value: Number, ctype: str) -> str:
        return double_literal(value) if ctype == "f64" else str(int(value))

    def concept(self, con: FieldRef) -> Concept:
        return self.concepts[con.field]

    def cname(self, con: FieldRef) -> str:
        return field_ident(con.field)

    def set_concept(self, con: FieldRef, value: str) -> list[str]:
        target = self.t(con)
        return [f"t.has_{self.cname(con)} = true;", f"{target} = {value};"]

    # -- values stored as the field holds them (backward) --------------------------------------

    def int_range(self, f: Field, p: PrimitiveType, hi: Number | None, marks: list[float | int]) -> tuple[int, int]:
        """Python's ``RuleContext.int_bounds``: the integers a converter may write into the field."""
        rng = allowed_range(p, f.range).intersect(self.rule_ranges.get(f))
        return writable_ints(p, rng, hi, marks)

    def store(self, fmt: FieldRef, expr: str, hi: Number | None = None, marks: tuple[Number, ...] = ()) -> str:
        """The f64 ``expr`` as the field holds it (Python's ``store``)."""
        f = self.fld(fmt)
        p = self.prim(fmt)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"r.f16_round_d({expr}, {self.label(fmt)})"
            return f"{paren(expr)} as f32" if p.bits == 32 else expr
        if p.kind is PrimitiveKind.BOOL:
            return f"{paren(expr)} != 0.0"
        lo, top = self.int_range(f, p, hi, self.markers(f, marks))
        return cast(f"r.round_int({expr}, {lo}, {top}, {self.label(fmt)})", "i64", scalar(p))

    def marked(self, target: str, fmt: FieldRef, mark: float | int, label: str) -> str:
        """A known value written as the field's marker is reported clamped."""
        add = f"r.add(LossKind::Clamped, {label});"
        return f"if {target} == {literal(self.prim(fmt), mark)} {{ {add} }}"

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
            text = f"{value}_i64"
        else:
            raise Unsupported(f"the constant {value!r} into {ref.field}")
        self.emit(*self.set_concept(ref, text))

    def when(self, tests: list[str], body: list[str]) -> list[str]:
        return [f"if {' && '.join(tests)} {{", *body, "}"] if tests else body

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
            self.emit(f"let v: {ctype} = {value};")
            tests = self.known_tests("v", ctype, marks)
            if op.valid_above is not None:
                tests.append(f"v > {self.bound(op.valid_above, ctype)}")
            if op.valid_max is not None:
                tests.append(f"v <= {self.bound(op.valid_max, ctype)}")
            out = affine(f64_of("v", ctype), mul, add) + (" + 0.0_f64" if negated and add == 0.0 else "")
            self.emit(*self.when(tests, self.set_concept(con, out)))
            return
        mul, add = unit_factor(c_unit, f_unit)
        if negated:
            mul = -mul
        target, label = self.t(fmt), self.label(fmt)
        name = self.cname(con)
        self.emit(f"if !s.has_{name} || s.{name}.is_nan() {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"r.add_u(LossKind::Unknown, {label});", "} else {")
        value = affine(f"s.{name}", mul, add) + (" + 0.0_f64" if negated and add == 0.0 else "")
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
        name = self.cname(con)
        if not self.backward:
            if kind == "text":
                self.text_in(fmt, con)
                return
            ctype, read = self.read_value(fmt)
            self.emit(f"let v: {ctype} = {read};")
            if kind == "bool":
                value = "v != 0.0" if ctype == "f64" else "v != 0"
            elif kind == "integer":
                if ctype == "f64":
                    raise Unsupported("a float copied into an integer concept")
                value = f"v + {int(add)}" if add else "v"
            else:
                value = f"{f64_of('v', ctype)} + {double_literal(add)}" if add else f64_of("v", ctype)
            tests = self.known_tests("v", ctype, marks)
            self.emit(*self.when(tests, self.set_concept(con, value)))
            return
        if kind == "text":
            self.text_out(fmt, con)
            return
        target, label = self.t(fmt), self.label(fmt)
        self.emit(f"if !s.has_{name} {{")
        if marks:
            self.emit(f"{target} = {literal(self.prim(fmt), marks[0])};")
        self.emit(f"r.add_u(LossKind::Unknown, {label});", "} else {")
        held = "f64" if kind == "number" else "i64"
        value = f64_of(f"s.{name}", held) + (f" - {double_literal(add)}" if add else "")
        if kind == "bool":
            value = f"(if s.{name} {{ 1.0_f64 }} else {{ 0.0_f64 }})"
        self.emit(f"{target} = {self.store(fmt, value, None, op.unknown)};")
        if kind != "bool":
            for m in (m for m in marks if not is_nan_value(m)):
                self.emit(self.marked(target, fmt, m, label))
        self.emit("}")

    def text_in(self, fmt: FieldRef, con: FieldRef) -> None:
        """Python's ``text_in``: a byte array up to its first NUL, decoded (invalid UTF-8 as U+FFFD); a
        MAVLink string's chars as they are; empty is unknown."""
        t = self.fld(fmt).type
        src, name = self.s(fmt), self.cname(con)
        self.written.add((CONCEPTS_ENDPOINT, con.field))
        if isinstance(t, StringType):
            self.emit(
                "let mut n = 0;",
                f"while n < {t.capacity or 0} && {src}[n] != 0 {{ t.{name}[n] = {src}[n]; n += 1; }}",
            )
        elif isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.element.bits == 8:
            count = f"{src}_len.min({capacity(t)})" if t.dynamic else f"{t.capacity or 0}"
            self.emit(
                "let mut n = 0;",
                f"while n < {count} && {src}[n] != 0 {{ n += 1; }}",
                f"let n = utf8_replace(&{src}[..n], &mut t.{name});",
            )
        else:
            raise Unsupported("text from a field that is not bytes")
        self.emit(f"t.{name}_len = n;", f"t.has_{name} = n > 0;")

    def text_out(self, fmt: FieldRef, con: FieldRef) -> None:
        """Unknown: the field's empty text; else a string gets the text, a byte array its UTF-8 bytes
        (Python's ``bytes_out``: beyond the capacity reported clamped and cut)."""
        f = self.fld(fmt)
        t = f.type
        target, label, name = self.t(fmt), self.label(fmt), self.cname(con)
        if not isinstance(t, StringType | ArrayType):
            raise Unsupported("text into a number")
        cap = t.capacity or 0
        dynamic = isinstance(t, ArrayType) and t.dynamic
        clear = f"{target}_len = 0;" if dynamic else f"{target} = [0; {capacity(t)}];"
        self.emit(f"if !s.has_{name} {{")
        if f.invalid is not None or dynamic:
            self.emit(clear)
        self.emit(f"r.add_u(LossKind::Unknown, {label});", "} else {")
        self.emit(f"let mut n = s.{name}_len;")
        self.emit(f"if n > {cap} {{ r.add(LossKind::Clamped, {label}); n = {cap}; }}")
        if not dynamic:
            self.emit(f"{target} = [0; {capacity(t)}];")
        self.emit(f"{target}[..n].copy_from_slice(&s.{name}[..n]);")
        if dynamic:
            self.emit(f"{target}_len = n;")
        self.emit("}")

    def visit_soc_hybrid(self, rule: Rule, op: o.SocHybrid) -> None:
        if self.backward:
            raise Unsupported("soc_hybrid backward")
        remaining, full = rule.sources[:2]
        con = rule.targets[0]
        self.emit(
            f"let e = {self.read_value(remaining)[1]};",
            f"let f = {self.read_value(full)[1]};",
            "if !e.is_nan() && !f.is_nan() && e > 0.0 && f > 0.0 {",
            "let q = e / f;",
            *self.set_concept(con, "if 1.0 < q { 1.0 } else { q }"),
        )
        if self.prim(remaining).kind is not PrimitiveKind.FLOAT or self.prim(full).kind is not PrimitiveKind.FLOAT:
            raise Unsupported("soc_hybrid of integers")
        if len(rule.sources) < 3:
            self.emit("}")
            return
        percent = rule.sources[2]
        f = self.fld(percent)
        mul, add = unit_factor(f.unit, self.concept(con).unit)
        ctype, read = self.read_value(percent)
        tests = self.known_tests("p", ctype, self.markers(f, op.unknown))
        if op.valid_max is not None:
            tests.append(f"p <= {self.bound(op.valid_max, ctype)}")
        self.emit(
            "} else {",
            f"let p: {ctype} = {read};",
            *self.when(tests, self.set_concept(con, affine(f64_of("p", ctype), mul, add))),
            "}",
        )

    def note_bits(self, fmt: FieldRef, mask: int) -> None:
        self.bit_masks[fmt.message, fmt.field] = self.bit_masks.get((fmt.message, fmt.field), 0) | mask

    def bits_of(self, fmt: FieldRef) -> str:
        return self.bits(self.s(fmt), self.rust(fmt))

    @staticmethod
    def bits(expr: str, rust: str) -> str:
        return f"u64::from({expr})" if rust == "bool" else cast(expr, rust, "u64")

    def visit_flag(self, rule: Rule, op: o.Flag) -> None:
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        name = self.cname(con)
        if self.backward:
            self.emit(f"if s.has_{name} && s.{name} {{ {self.t(fmt)} |= {mask}; }}")
            return
        self.note_bits(fmt, mask)
        self.emit(*self.set_concept(con, f"({self.bits_of(fmt)} & {mask}) != 0"))

    def visit_flag_choice(self, rule: Rule, op: o.FlagChoice) -> None:
        fmt, con = self.format_and_concept(rule)
        mask = self.mask(op.mask, [fmt])
        code = choice_name(con.field, op.value)
        if self.backward:
            name = self.cname(con)
            self.emit(f"if s.has_{name} && s.{name} == {code} {{ {self.t(fmt)} |= {mask}; }}")
            return
        self.note_bits(fmt, mask)
        self.emit(f"if ({self.bits_of(fmt)} & {mask}) != 0 {{", *self.set_concept(con, code), "}")

    def visit_flags(self, rule: Rule, op: o.Flags) -> None:
        fmt, con = self.format_and_concept(rule)
        concept = self.concept(con)
        table = {bit.choice: self.mask(bit.mask, [fmt]) for bit in op.map}
        ordered = [(c, table[c]) for c in concept.choices if c in table]
        name = self.cname(con)
        if not self.backward:
            self.note_bits(fmt, sum(table.values()))
            self.emit(f"let v = {self.bits_of(fmt)};", "let mut b = 0_u32;")
            for choice, mask in ordered:
                self.emit(f"if (v & {mask}) != 0 {{ b |= {choice_name(con.field, choice)}; }}")
            self.emit(*self.set_concept(con, "b"))
            return
        target, label = self.t(fmt), self.label(fmt)
        rust = self.rust(fmt)
        others = " | ".join(choice_name(con.field, c) for c in concept.choices if c not in table) or "0"
        self.emit(
            f"if !s.has_{name} {{",
            f"r.add_u(LossKind::Unknown, {label});",
            "} else {",
            f"let mut b = {self.bits(target, rust)};",
        )
        for choice, mask in ordered:
            self.emit(f"if (s.{name} & {choice_name(con.field, choice)}) != 0 {{ b |= {mask}; }}")
        self.emit(
            f"{target} = {cast('b', 'u64', rust)};",
            f"if (s.{name} & ({others})) != 0 {{",
            f'r.add_d(LossKind::Dropped, "concepts.{con.field}");',
            "}",
            "}",
        )

    def visit_choice(self, rule: Rule, op: o.Choice) -> None:
        fmt, con = self.format_and_concept(rule)
        table = [(entry.choice, self.value_of(entry.value, [fmt])) for entry in op.map]
        unknown = self.value_of(op.unknown, [fmt]) if op.unknown is not None else None
        p = self.prim(fmt)
        name = self.cname(con)
        if not self.backward:
            ctype, read = self.read_value(fmt)
            if ctype != "i64":
                raise Unsupported("a choice read from a float")
            by_value: dict[object, str] = {}
            for choice, value in table:
                by_value[value] = choice  # the last wins, as Python's dict
            self.emit(f"let v: i64 = {read};", f"t.has_{name} = true;", "match v {")
            for value, choice in by_value.items():
                self.emit(f"{int(value)} => {self.t(con)} = {choice_name(con.field, choice)},")  # type: ignore[call-overload]
            skip = "" if unknown is None else f"if v != {int(unknown)} "  # type: ignore[call-overload]
            self.emit(
                "_ => {",
                f"t.has_{name} = false;",
                f"{skip}{{ r.add_d(LossKind::Dropped, {self.label(fmt)}); }}",
                "}",
                "}",
            )
            return
        target, label = self.t(fmt), self.label(fmt)
        by_choice: dict[str, object] = {}
        for choice, value in table:
            by_choice[choice] = value
        self.emit("let mut w = false;", f"if s.has_{name} {{")
        for k, (choice, value) in enumerate(by_choice.items()):
            head = "if" if k == 0 else "} else if"
            self.emit(f"{head} s.{name} == {choice_name(con.field, choice)} {{", f"{target} = {literal(p, value)};")
            self.emit("w = true;")
        self.emit(*(["}"] if by_choice else []), "}", "if !w {")
        if unknown is not None:
            self.emit(f"{target} = {literal(p, unknown)};")
        self.emit(
            f"r.add_u(LossKind::Unknown, {label});",
            f'if s.has_{name} {{ r.add_d(LossKind::Dropped, "concepts.{con.field}"); }}',
            "}",
        )
