"""What a field's type, schema range, sentinel and enum groups allow: the facts the generated
checks and their specs are built from (also what the JSON Schema conformance test compares)."""

from __future__ import annotations

from dataclasses import dataclass

from ....ir import EnumKind, Field, PrimitiveKind, PrimitiveType, Range, Schema, allowed_range
from ..literals import py_literal


@dataclass(frozen=True)
class EnumFacts:
    """What a field's enum groups allow."""

    values: dict[int, str] | None  # value enums: value -> member name
    mask: int | None  # bitmask / bit-index enums: bits that may be set
    bits: dict[int, str]  # bit value -> member name (reserved members included)


def enum_facts(schema: Schema, f: Field) -> EnumFacts | None:
    if not f.enums:
        return None
    values: dict[int, str] = {}
    mask: int | None = None
    bits: dict[int, str] = {}
    for name in f.enums:
        e = schema.enum(name)
        for entry in e.entries:
            if e.kind is EnumKind.VALUE:
                values.setdefault(entry.value, entry.name)
                continue
            bit = entry.value if e.kind is EnumKind.BITMASK else 1 << entry.value
            bits.setdefault(bit, entry.name)
            # members named *RESERVED* document bits that must stay zero
            if "RESERVED" not in entry.name.upper():
                mask = (mask or 0) | bit
        if e.kind is not EnumKind.VALUE and mask is None:
            mask = 0
    if mask is not None:
        return EnumFacts(None, mask, bits)
    return EnumFacts(values, None, bits)


@dataclass(frozen=True)
class Bounds:
    """The interval a primitive value must lie in (type width folded with the schema range)."""

    low: float
    high: float
    low_strict: bool
    high_strict: bool


def folded(t: PrimitiveType, rng: Range | None) -> Bounds:
    r = allowed_range(t, rng)
    assert r.minimum is not None and r.maximum is not None
    return Bounds(r.minimum, r.maximum, r.exclusive_minimum, r.exclusive_maximum)


def inside(b: Bounds, value: float) -> bool:
    above = value > b.low if b.low_strict else value >= b.low
    below = value < b.high if b.high_strict else value <= b.high
    return above and below


def number(value: float, t: PrimitiveType) -> str:
    if t.kind is PrimitiveKind.FLOAT:
        return py_literal(float(value))
    return py_literal(int(value)) if float(value).is_integer() else py_literal(value)
