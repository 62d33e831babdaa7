"""What a field means beyond its type: range, per-position columns, invalid sentinel, enums, constants."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from .basics import Location, Unit
from .fieldtypes import FieldType, PrimitiveKind, PrimitiveType, Range, StringType


@dataclass(frozen=True)
class Sentinel:
    """The value that means "unknown / invalid".

    ``text`` keeps the spelling of the source (``INT16_MAX``, ``NaN``); ``value`` is the number
    (``float('nan')`` for NaN). ``per_element`` marks an array whose elements each carry it; on a
    text field (``char[N]``, a StringType) it is the byte value of every character, so ``0`` per
    element is the empty string (PX4's ``[@invalid 0]`` "all bytes zero").
    ``elements`` is for a marker given per position (MAVLink's ``[v1,,v3,]``, ``[0,]``): the marker
    of each leading element, None where the list leaves one out; elements past the list have no
    marker. It is empty for the other forms; when set, ``value`` is its first marker.
    ``first_decides`` is MAVLink's ``[X:]``: the whole array is unknown when its first element is
    ``value`` (the other elements then mean nothing, whatever they hold); it is not per element.
    """

    value: int | float
    text: str
    per_element: bool = False
    elements: tuple[int | float | None, ...] = ()
    first_decides: bool = False

    @property
    def is_nan(self) -> bool:
        return _is_nan(self.value)

    def matches(self, value: object) -> bool:
        if self.is_nan:
            return isinstance(value, float) and math.isnan(value)
        return bool(value == self.value)

    def marker_at(self, index: int) -> int | float | None:
        """The marker of array element ``index`` (None when that element has none)."""
        if not self.elements:
            return self.value
        return self.elements[index] if 0 <= index < len(self.elements) else None

    def _key(self) -> tuple[object, ...]:
        def norm(v: int | float | None) -> object:
            return "nan" if v is not None and _is_nan(v) else v

        elements = tuple(norm(v) for v in self.elements)
        return (norm(self.value), self.text, self.per_element, elements, self.first_decides)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sentinel):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())


def _is_nan(value: int | float) -> bool:
    return isinstance(value, float) and math.isnan(value)


class EnumKind(str, enum.Enum):
    VALUE = "value"  # the field holds one of the entries
    BITMASK = "bitmask"  # entries are masks (1, 2, 4, ...) OR-ed together
    BIT_INDEX = "bit_index"  # entries are bit positions (0, 1, 2, ...) in a bitmask field


@dataclass(frozen=True)
class EnumEntry:
    name: str
    value: int
    doc: str = ""
    location: Location | None = None


@dataclass(frozen=True)
class EnumDef:
    """A named group of values. ``name`` is qualified (``uorb.BatteryStatus.WARNING``)."""

    name: str
    kind: EnumKind
    entries: tuple[EnumEntry, ...]
    doc: str = ""
    location: Location | None = None

    @property
    def short_name(self) -> str:
        return self.name.rsplit(".", 1)[-1]


@dataclass(frozen=True)
class Constant:
    name: str
    type: PrimitiveType | StringType
    value: int | float | bool | str
    doc: str = ""
    location: Location | None = None


@dataclass(frozen=True)
class Field:
    """One field of a message (or property of a devicetree node).

    ``name`` is the source spelling (``voltage-min-design-microvolt``); backends pick identifiers.
    ``enums`` names the enum groups (qualified) the value draws on, in the order the schema lists.
    """

    name: str
    type: FieldType
    location: Location
    doc: str = ""
    unit: Unit | None = None
    unit_text: str | None = None
    range: Range | None = None
    invalid: Sentinel | None = None
    enums: tuple[str, ...] = ()
    extension: bool = False  # MAVLink 2 extension field
    pattern: str | None = None  # devicetree patternProperties: the name is a regular expression
    required: bool = False
    const: str | int | None = None
    choices: tuple[str | int, ...] = ()
    default: int | float | bool | str | None = None
    annotations: tuple[tuple[str, str], ...] = ()  # source annotations kept verbatim (tag, text)
    frame: str | None = None  # coordinate frame the value is expressed in, as the source names it (NED, FRD, ...)

    @property
    def is_padding(self) -> bool:
        return isinstance(self.type, PrimitiveType) and self.type.kind is PrimitiveKind.VOID
