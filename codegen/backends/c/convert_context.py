"""What every C converter emitter works with: the function being written and facts about its
fields (see :mod:`.converters`)."""

from __future__ import annotations

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
from .types import ident, scalar


class CBase:
    """One direction of one mapping being written as C statements: its two sides (an endpoint's
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
        return f"{prefix}_{ident(side.aliases[side.messages.index(qualified)])}"

    def optional(self, qualified: str) -> bool:
        return self.src is not None and self.src.messages.index(qualified) > 0

    def fld(self, ref: FieldRef) -> Field:
        return self.schema.field_at(ref.message, ref.field)

    def attr(self, ref: FieldRef) -> str:
        head, *steps = ref.field.split(".")
        out = ident(head)
        t = self.schema.message(ref.message).field(head).type
        for step in steps:
            if isinstance(t, ArrayType):
                out += f"[{int(step)}]"
                t = t.element
            else:
                assert isinstance(t, CompositeType), ref
                out += "." + ident(step)
                t = self.schema.message(t.name).field(step).type
        return out

    def s(self, ref: FieldRef) -> str:
        self.read.add((ref.message, ref.field))
        if ref.message == CONCEPTS_ENDPOINT:
            return f"s->{ident(ref.field)}"
        self.read.add((ref.message, ref.field.split(".")[0]))
        return f"{self.var(self.src, ref.message, 's')}->{self.attr(ref)}"

    def t(self, ref: FieldRef) -> str:
        self.written.add((ref.message, ref.field))
        self.written.add((ref.message, ref.field.split(".")[0]))
        if ref.message == CONCEPTS_ENDPOINT:
            return f"t->{ident(ref.field)}"
        return f"{self.var(self.dst, ref.message, 't')}->{self.attr(ref)}"

    def label(self, ref: FieldRef) -> str:
        return f'"{ref.message}.{ref.field}"'

    def prim(self, ref: FieldRef) -> PrimitiveType:
        p = primitive(self.fld(ref))
        if p is None:
            raise Unsupported(f"{ref.field} is not a number")
        return p

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
        """A source value in a C float; a DroneCAN float16 as it came off the wire."""
        value = expr or self.s(ref)
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT and p.bits == 16:
            return f"battgen_f16_round({value}, NULL, NULL)"
        if p.kind is PrimitiveKind.FLOAT and p.bits == 32:
            return value
        if p.kind is PrimitiveKind.BOOL:
            return f"({value} ? 1.0f : 0.0f)"
        return f"(float){value}"

    def store_c(self, ref: FieldRef, expr: str) -> str:
        """A C assignment of the float32 ``expr`` to the field's type (then DroneCAN's saturation)."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"battgen_f16_round({expr}, rep, {self.label(ref)})"
            return expr if p.bits == 32 else f"(double)({expr})"
        if p.kind is PrimitiveKind.BOOL:
            return f"(({expr}) != 0.0f)"
        signed = p.kind is PrimitiveKind.INT
        c = scalar(p)
        storage = int(c.removeprefix("u").removeprefix("int")[:-2])
        fn = f"cvt_{'i' if signed else 'u'}{storage}" + ("" if storage == p.bits else f"_{p.bits}")
        self.helper_cvt(fn, c, signed, storage, p)
        return f"{fn}({expr}, rep, {self.label(ref)})"

    def helper_cvt(self, fn: str, c: str, signed: bool, storage: int, p: PrimitiveType) -> None:
        body = [f"static {c} {fn}(float x, battgen_loss_report *rep, const char *field) {{"]
        if signed:
            body.append(f"{c} v = battgen_i{storage}((uint{storage}_t)(uint32_t)battgen_vcvt_s32(x));")
        else:
            body.append(f"{c} v = ({c})battgen_vcvt_u32(x);")
        body.append(
            "if (battgen_float_int_lost(x, (int64_t)v)) { battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field); }"
        )
        if storage != p.bits:  # DroneCAN's saturated odd width
            lo, hi = (int(v) for v in p.value_range or (0, 0))
            body.append(f"if (v < {int_literal(lo, c)}) {{ v = {int_literal(lo, c)}; }}" if signed else "")
            body.append(f"if (v > {int_literal(hi, c)}) {{ v = {int_literal(hi, c)}; }}")
        body += ["return v;", "}"]
        self.helpers[fn] = [line for line in body if line]

    def int_store(self, ref: FieldRef, expr: str) -> str:
        """The integer ``expr`` (an int64_t) as C keeps it in the field, then a DroneCAN odd width saturated."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.BOOL:
            return f"(({expr}) != 0)"
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer into a float field")
        c = scalar(p)
        storage = int(c.removeprefix("u").removeprefix("int")[:-2])
        raw = f"(uint{storage}_t)(uint64_t)({expr})"
        value = raw if p.kind is PrimitiveKind.UINT else f"battgen_i{storage}({raw})"
        if storage == p.bits:
            return value
        lo, hi = (int(v) for v in p.value_range or (0, 0))
        fn = f"saturate_{c[:-2]}_{p.bits}"
        self.helpers[fn] = [
            f"static {c} {fn}({c} v) {{",
            *([f"if (v < {int_literal(lo, c)}) {{ return {int_literal(lo, c)}; }}"] if lo < 0 else []),
            f"return v > {int_literal(hi, c)} ? {int_literal(hi, c)} : v;",
            "}",
        ]
        return f"{fn}({value})"

    def int_source(self, ref: FieldRef) -> str:
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer op on a float")
        return f"(int64_t){self.s(ref)}"
