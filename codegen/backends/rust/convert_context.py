"""What every Rust converter emitter works with: the function being written and facts about its
fields (see :mod:`.converters`; the C backend's ``convert_context``, in Rust). A source message
after an endpoint's first is optional (``Option<&T>``): the rules reading it run inside
``if let Some(..)``, which rebinds its name to the message."""

from __future__ import annotations

import re

from ...ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    CompositeType,
    Concept,
    Endpoint,
    Field,
    FieldRef,
    Mapping,
    PrimitiveKind,
    PrimitiveType,
    Schema,
)
from ...ir.mapping_values import ConstantRef, Value
from ...ir.rules import rule_ranges
from .convert_values import Unsupported, int_literal, primitive
from .naming import field_ident, snake
from .types import scalar


def paren(expr: str) -> str:
    """``expr`` as an operand: in parentheses unless it is a place or already parenthesised."""
    if re.fullmatch(r"[\w.\[\]]+", expr):
        return expr
    if expr.startswith("("):
        depth = 0
        for i, ch in enumerate(expr):
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if depth == 0:
                if i == len(expr) - 1:
                    return expr
                break
    return f"({expr})"


def cast(expr: str, frm: str, to: str) -> str:
    """``expr`` (of Rust type ``frm``) as ``to``, unparenthesised: no cast where it is one already (clippy)."""
    return expr if frm == to else f"{paren(expr)} as {to}"


class RustBase:
    """One direction of one mapping being written as Rust statements: its two sides (an endpoint's
    messages, or the concepts: ``None``), the lines so far, the fields read and written."""

    def __init__(
        self,
        schema: Schema,
        mapping: Mapping,
        src: Endpoint | None,
        dst: Endpoint | None,
        backward: bool,
        concepts: dict[str, Concept],
        helpers: dict[str, list[str]],
    ) -> None:
        self.schema = schema
        # the ranges rules state of single fields: a converter keeps to them as to the schema's own
        self.rule_ranges = {schema.field_at(m, name): rng for (m, name), rng in rule_ranges(schema).items()}
        self.bit_masks: dict[tuple[str, str], int] = {}  # source bits some rule reads
        self.backward = backward
        self.concepts = concepts
        self.helpers = helpers  # functions the converters share, by name
        self.mapping = mapping
        self.src = src
        self.dst = dst
        self.lines: list[str] = []
        self.inputs: list[str] = []
        self.read: set[tuple[str, str]] = set()
        self.written: set[tuple[str, str]] = set()

    # -- names -----------------------------------------------------------------------------

    def var(self, side: Endpoint | None, qualified: str, prefix: str) -> str:
        if side is None:
            return prefix
        return f"{prefix}_{snake(side.aliases[side.messages.index(qualified)])}"

    def optional(self, qualified: str) -> bool:
        return self.src is not None and self.src.messages.index(qualified) > 0

    def fld(self, ref: FieldRef) -> Field:
        return self.schema.field_at(ref.message, ref.field)

    def attr(self, ref: FieldRef) -> str:
        head, *steps = ref.field.split(".")
        out = field_ident(head)
        t = self.schema.message(ref.message).field(head).type
        for step in steps:
            if isinstance(t, ArrayType):
                out += f"[{int(step)}]"
                t = t.element
            else:
                assert isinstance(t, CompositeType), ref
                out += "." + field_ident(step)
                t = self.schema.message(t.name).field(step).type
        return out

    def concept_field(self, name: str) -> str:
        return field_ident(name)

    def s(self, ref: FieldRef) -> str:
        self.read.add((ref.message, ref.field))
        if ref.message == CONCEPTS_ENDPOINT:
            return f"s.{self.concept_field(ref.field)}"
        self.read.add((ref.message, ref.field.split(".")[0]))
        return f"{self.var(self.src, ref.message, 's')}.{self.attr(ref)}"

    def t(self, ref: FieldRef) -> str:
        self.written.add((ref.message, ref.field))
        self.written.add((ref.message, ref.field.split(".")[0]))
        if ref.message == CONCEPTS_ENDPOINT:
            return f"t.{self.concept_field(ref.field)}"
        return f"{self.var(self.dst, ref.message, 't')}.{self.attr(ref)}"

    def label(self, ref: FieldRef) -> str:
        return f'"{ref.message}.{ref.field}"'

    def prim(self, ref: FieldRef) -> PrimitiveType:
        p = primitive(self.fld(ref))
        if p is None:
            raise Unsupported(f"{ref.field} is not a number")
        return p

    def rust(self, ref: FieldRef) -> str:
        """The Rust type of a field's value (an array's element)."""
        return scalar(self.prim(ref))

    def constant_value(self, name: str, refs: tuple[FieldRef, ...] | list[FieldRef]) -> int | float | bool | str:
        for ref in refs:
            if ref.message == CONCEPTS_ENDPOINT:
                continue
            for c in self.schema.message(ref.message).constants:
                if c.name == name:
                    return c.value
        for e in self.schema.enums:
            for entry in e.entries:
                if entry.name == name:
                    return entry.value
        raise Unsupported(f"no constant {name!r}")

    def value_of(self, value: Value | None, refs: tuple[FieldRef, ...] | list[FieldRef]) -> object:
        return self.constant_value(value.name, refs) if isinstance(value, ConstantRef) else value

    def mask(self, name: ConstantRef, refs: tuple[FieldRef, ...] | list[FieldRef]) -> int:
        value = self.constant_value(name.name, refs)
        for ref in refs:
            if ref.message == CONCEPTS_ENDPOINT:
                continue
            for e in self.schema.message(ref.message).enums:
                if any(x.name == name.name for x in e.entries) and e.kind.value == "bit_index":
                    return 1 << int(value)
        return int(value)

    def concept_const(self, ref: FieldRef, value: object) -> None:
        raise Unsupported("a constant into a concept")

    def emit(self, *lines: str) -> None:
        self.lines.extend(lines)

    # -- values as PX4 holds them --------------------------------------------------------

    def px4_read(self, ref: FieldRef, expr: str | None = None) -> str:
        """A source value as an f32; a DroneCAN float16 as it came off the wire."""
        value = expr or self.s(ref)
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT and p.bits == 16:
            return f"f16_round({value}).0"
        if p.kind is PrimitiveKind.FLOAT and p.bits == 32:
            return value
        if p.kind is PrimitiveKind.BOOL:
            return f"(if {value} {{ 1.0_f32 }} else {{ 0.0_f32 }})"
        return f"{paren(value)} as f32"

    def store_c(self, ref: FieldRef, expr: str) -> str:
        """A C assignment of the f32 ``expr`` to the field's type (then DroneCAN's saturation)."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"r.f16_round({expr}, {self.label(ref)})"
            return expr if p.bits == 32 else f"f64::from({expr})"
        if p.kind is PrimitiveKind.BOOL:
            return f"{paren(expr)} != 0.0"
        signed = p.kind is PrimitiveKind.INT
        rust = scalar(p)
        storage = int(rust[1:])
        fn = f"cvt_{'i' if signed else 'u'}{storage}" + ("" if storage == p.bits else f"_{p.bits}")
        self.helper_cvt(fn, rust, signed, storage, p)
        return f"{fn}({expr}, r, {self.label(ref)})"

    def helper_cvt(self, fn: str, rust: str, signed: bool, storage: int, p: PrimitiveType) -> None:
        body = [f"fn {fn}(x: f32, r: &mut Reports<'_>, field: &'static str) -> {rust} {{"]
        if signed:  # C: the VCVT int32's low bits, a 64-bit field taking them zero-extended
            wide = "(x as i32 as u32 as u64 as i64)" if storage == 64 else cast("x as i32", "i32", rust)
            body.append(f"let mut v = {wide};" if storage != p.bits else f"let v = {wide};")
        else:
            wide = "u64::from(x as u32)" if storage == 64 else cast("x as u32", "u32", rust)
            body.append(f"let mut v = {wide};" if storage != p.bits else f"let v = {wide};")
        kept = "v" if rust == "i64" else ("(v as i64)" if rust == "u64" else "i64::from(v)")
        body.append(f"if float_int_lost(x, {kept}) {{ r.add(LossKind::Clamped, field); }}")
        if storage != p.bits:  # DroneCAN's saturated odd width
            lo, hi = (int(v) for v in p.value_range or (0, 0))
            if signed:
                body.append(f"if v < {int_literal(lo, rust)} {{ v = {int_literal(lo, rust)}; }}")
            body.append(f"if v > {int_literal(hi, rust)} {{ v = {int_literal(hi, rust)}; }}")
        body += ["v", "}"]
        self.helpers[fn] = body

    def int_store(self, ref: FieldRef, expr: str) -> str:
        """The integer ``expr`` (an i64) as C keeps it in the field, then a DroneCAN odd width saturated."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.BOOL:
            return f"{paren(expr)} != 0"
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer into a float field")
        rust = scalar(p)
        storage = int(rust[1:])
        value = cast(expr, "i64", rust)  # the low bits, as C's conversions keep them
        if storage == p.bits:
            return value
        lo, hi = (int(v) for v in p.value_range or (0, 0))
        fn = f"saturate_{rust}_{p.bits}"
        self.helpers[fn] = [
            f"fn {fn}(v: {rust}) -> {rust} {{",
            *([f"if v < {int_literal(lo, rust)} {{ return {int_literal(lo, rust)}; }}"] if lo < 0 else []),
            f"if v > {int_literal(hi, rust)} {{ {int_literal(hi, rust)} }} else {{ v }}",
            "}",
        ]
        return f"{fn}({value})"

    def int_source(self, ref: FieldRef) -> str:
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer op on a float")
        return self.as_i64(self.s(ref), scalar(p))

    @staticmethod
    def as_i64(expr: str, rust: str) -> str:
        if rust == "bool":
            return f"i64::from({expr})"
        return cast(expr, rust, "i64")
