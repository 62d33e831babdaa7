"""Field types with their exact width (primitives, arrays, strings, references to composites), and the
bounds an array may set per position (``Range``, ``Column``)."""

from __future__ import annotations

import enum
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass

from .basics import Location, Unit


@dataclass(frozen=True)
class Range:
    """Inclusive bounds unless marked exclusive; either side may be open (None)."""

    minimum: int | float | None = None
    maximum: int | float | None = None
    exclusive_minimum: bool = False
    exclusive_maximum: bool = False

    def intersect(self, other: Range | None) -> Range:
        """The values both ranges allow (the tighter bound on each side)."""
        if other is None:
            return self
        lo, lo_x = _tighter(self.minimum, self.exclusive_minimum, other.minimum, other.exclusive_minimum, max)
        hi, hi_x = _tighter(self.maximum, self.exclusive_maximum, other.maximum, other.exclusive_maximum, min)
        return Range(lo, hi, lo_x, hi_x)


def _tighter(
    a: int | float | None, a_x: bool, b: int | float | None, b_x: bool, pick: Callable[..., int | float]
) -> tuple[int | float | None, bool]:
    if a is None:
        return b, b_x
    if b is None:
        return a, a_x
    if a == b:
        return a, a_x or b_x
    return (a, a_x) if pick(a, b) == a else (b, b_x)


@dataclass(frozen=True)
class Column:
    """What one position of an array holds: element ``i`` of an ``ArrayType`` with ``columns``.

    Its constraints add to the field's (both hold); ``range`` applies to every number element
    ``i`` holds (the element itself, or each number of a row when the element is an array);
    ``unit`` None means the field's unit.
    """

    doc: str = ""
    unit: Unit | None = None
    range: Range | None = None
    location: Location | None = None


class PrimitiveKind(str, enum.Enum):
    BOOL = "bool"
    UINT = "uint"
    INT = "int"
    FLOAT = "float"
    CHAR = "char"  # MAVLink / uORB char: a byte of a fixed-size string
    VOID = "void"  # DSDL padding bits; fields of this kind have no name


class CastMode(str, enum.Enum):
    SATURATED = "saturated"
    TRUNCATED = "truncated"


@dataclass(frozen=True)
class PrimitiveType:
    kind: PrimitiveKind
    bits: int
    cast: CastMode = CastMode.SATURATED

    @property
    def name(self) -> str:
        """The type as a schema would spell it: ``uint11``, ``float16``, ``bool``, ``void5``."""
        if self.kind is PrimitiveKind.BOOL:
            return "bool"
        if self.kind is PrimitiveKind.CHAR:
            return "char"
        return f"{self.kind.value}{self.bits}"

    @property
    def value_range(self) -> tuple[float, float] | None:
        """The representable range of an integer or float type (None for void/char)."""
        if self.kind is PrimitiveKind.BOOL:
            return (0, 1)
        if self.kind is PrimitiveKind.UINT:
            return (0, (1 << self.bits) - 1)
        if self.kind is PrimitiveKind.INT:
            return (-(1 << (self.bits - 1)), (1 << (self.bits - 1)) - 1)
        if self.kind is PrimitiveKind.FLOAT:
            return {16: (-65504.0, 65504.0), 32: (-3.4028234663852886e38, 3.4028234663852886e38)}.get(
                self.bits, (-math.inf, math.inf)
            )
        return None


# The largest array capacity a frontend accepts (README "Limits"): four times the largest upstream one
# (PX4 512, DroneCAN 300, dtschema maxItems 1024, MAVLink 255). The generated codecs, column lists and
# the data readers' loops are sized by capacities, so an absurd one must not reach them.
MAX_ARRAY_CAPACITY = 4096


@dataclass(frozen=True)
class ArrayType:
    """A fixed (``dynamic=False``) or bounded-dynamic array; ``capacity`` None means unbounded.

    ``columns[i]`` constrains element ``i`` only (JSON Schema's ``prefixItems``); elements past
    the last column have only the field's constraints. A matrix whose rows are (OCV, percent)
    puts its columns on the row type, the inner array. They live on the type rather than the
    Field because a position is a property of one array level: the type says at which depth it
    applies, and it travels with the type through every backend that walks element types.
    """

    element: FieldType
    capacity: int | None
    dynamic: bool
    min_length: int = 0
    columns: tuple[Column, ...] = ()


@dataclass(frozen=True)
class StringType:
    """A text value: a devicetree string, or a NUL-padded char array of ``capacity`` bytes."""

    capacity: int | None = None


@dataclass(frozen=True)
class CompositeType:
    """A reference to another message by its qualified name."""

    name: str


FieldType = PrimitiveType | ArrayType | StringType | CompositeType


# The largest finite value of each float width (IEEE 754 binary16/32/64)
FLOAT_MAX: dict[int, float] = {16: 65504.0, 32: 3.4028234663852886e38, 64: sys.float_info.max}


def type_bounds(t: PrimitiveType, rng: Range | None) -> tuple[float, float]:
    """The values type ``t`` holds: an integer's width, a float's finite range; a float may be
    -inf/+inf only where the schema's range explicitly reaches it."""
    if t.kind is PrimitiveKind.FLOAT:
        top = FLOAT_MAX.get(t.bits, sys.float_info.max)
        low = -math.inf if rng is not None and rng.minimum == -math.inf else -top
        high = math.inf if rng is not None and rng.maximum == math.inf else top
        return low, high
    bounds = t.value_range
    assert bounds is not None, f"{t.name} has no numeric range"
    return bounds


def allowed_range(t: PrimitiveType, rng: Range | None) -> Range:
    """The interval a value of type ``t`` must lie in: the type's bounds folded with the schema's range."""
    low, high = type_bounds(t, rng)
    return Range(low, high).intersect(rng)


def writable_ints(t: PrimitiveType, rng: Range, hi: float | None, marks: list[float | int]) -> tuple[int, int]:
    """The integers a converter may write into an integer field of type ``t`` whose values must lie in
    ``rng`` (the schema's range with a rule's, :func:`allowed_range`), at most ``hi``, less a marker at
    either end -- a value clamped onto it would read as unknown. Both backends' converters clamp to it."""
    type_lo, type_hi = (int(v) for v in t.value_range or (0, 0))
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
    numbers = [m for m in marks if not (isinstance(m, float) and math.isnan(m))]
    while lo < top and lo in numbers:
        lo += 1
    while top > lo and top in numbers:
        top -= 1
    return (lo, top) if lo <= top else (type_lo, type_hi)
