"""The intermediate representation (IR): one small, frozen type model for every schema format.

Frontends produce these objects and nothing else; backends consume them and nothing else.
Every object is immutable and hashable, so an IR can be cached, compared and shared freely.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from .expr import RuleExpressions
from .ops import MappingOp


class SourceFormat(str, enum.Enum):
    UORB = "uorb"
    DRONECAN = "dronecan"
    DEVICETREE = "devicetree"
    MAVLINK = "mavlink"
    PARAMS = "params"  # ArduPilot parameter metadata (apm.pdef.xml)


@dataclass(frozen=True)
class Location:
    """Where a definition came from: the file as given to the frontend and a 1-based line."""

    file: str
    line: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


# --------------------------------------------------------------------------------------------
# Units


@dataclass(frozen=True)
class Unit:
    """A unit of measure, related to its quantity's base unit by ``base = value * scale + offset``.

    ``symbol`` is canonical (``mV``, ``degC``); two units of one ``quantity`` convert into each
    other through their ``scale`` and ``offset`` alone, so converters derive factors from the IR.
    """

    symbol: str
    quantity: str
    base: str
    scale: float = 1.0
    offset: float = 0.0

    def factor_to(self, other: Unit) -> tuple[float, float]:
        """(multiplier, addend) turning a value in this unit into ``other``."""
        if self.quantity != other.quantity:
            raise ValueError(f"cannot convert {self.symbol} ({self.quantity}) to {other.symbol} ({other.quantity})")
        mul = self.scale / other.scale
        add = (self.offset - other.offset) / other.scale
        return mul, add


# --------------------------------------------------------------------------------------------
# Types


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


# --------------------------------------------------------------------------------------------
# Field semantics


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


@dataclass(frozen=True)
class Sentinel:
    """The value that means "unknown / invalid".

    ``text`` keeps the spelling of the source (``INT16_MAX``, ``NaN``); ``value`` is the number
    (``float('nan')`` for NaN). ``per_element`` marks an array whose elements each carry it.
    """

    value: int | float
    text: str
    per_element: bool = False

    @property
    def is_nan(self) -> bool:
        return isinstance(self.value, float) and math.isnan(self.value)

    def matches(self, value: object) -> bool:
        if self.is_nan:
            return isinstance(value, float) and math.isnan(value)
        return bool(value == self.value)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sentinel):
            return NotImplemented
        same = (self.is_nan and other.is_nan) or self.value == other.value
        return same and self.text == other.text and self.per_element == other.per_element

    def __hash__(self) -> int:
        return hash(("nan" if self.is_nan else self.value, self.text, self.per_element))


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

    @property
    def is_padding(self) -> bool:
        return isinstance(self.type, PrimitiveType) and self.type.kind is PrimitiveKind.VOID


# --------------------------------------------------------------------------------------------
# Per-format facts


@dataclass(frozen=True)
class StructSlot:
    """One member of a C struct: a field, or padding (``field`` None)."""

    name: str
    offset: int
    size: int
    field: str | None


@dataclass(frozen=True)
class UorbInfo:
    message_version: int | None
    topics: tuple[str, ...]
    struct_size: int  # sizeof the C struct, padding included
    layout: tuple[StructSlot, ...]  # fields sorted by element size (stable) with PX4's padding


class DronecanKind(str, enum.Enum):
    MESSAGE = "message"
    REQUEST = "request"
    RESPONSE = "response"


@dataclass(frozen=True)
class DronecanInfo:
    full_name: str  # DSDL name, e.g. uavcan.equipment.power.BatteryInfo
    data_type_id: int | None
    signature: int  # 64-bit data type signature, as pydronecan computes it
    kind: DronecanKind
    union: bool
    min_bitlen: int
    max_bitlen: int
    min_bitlen_tao: int  # with tail-array optimisation applied to the last field
    max_bitlen_tao: int
    normalized_definition: str


@dataclass(frozen=True)
class MavlinkInfo:
    msg_id: int
    crc_extra: int
    dialect: str
    wire_order: tuple[str, ...]  # base fields sorted by type size, then extensions
    base_length: int  # payload bytes without extensions (MAVLink 1 length)
    max_length: int  # payload bytes with extensions


@dataclass(frozen=True)
class DevicetreeInfo:
    schema_id: str
    title: str
    compatible: tuple[str, ...]
    required: tuple[str, ...]
    additional_properties: bool
    maintainers: tuple[str, ...] = ()


@dataclass(frozen=True)
class ParamsInfo:
    """An ArduPilot parameter group: ``prefix`` joins group and parameter (``BATT_``); ``section``
    is where apm.pdef.xml lists it (``libraries`` or ``vehicles``)."""

    prefix: str
    section: str


@dataclass(frozen=True)
class Message:
    """A message, service half, or devicetree node type.

    ``qualified_name`` is prefixed by the format and mirrors the generated module layout
    (``dronecan.uavcan.equipment.power.BatteryInfo``, ``mavlink.BATTERY_STATUS``).
    ``constants`` holds every constant, enum members included; ``enums`` groups them.
    """

    name: str
    qualified_name: str
    format: SourceFormat
    location: Location
    doc: str
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...] = ()
    enums: tuple[EnumDef, ...] = ()
    uorb: UorbInfo | None = None
    dronecan: DronecanInfo | None = None
    mavlink: MavlinkInfo | None = None
    devicetree: DevicetreeInfo | None = None
    params: ParamsInfo | None = None

    def field(self, name: str) -> Field:
        for f in self.fields:
            if f.name == name:
                return f
        raise KeyError(name)


# --------------------------------------------------------------------------------------------
# Concepts and mappings (schemas/mappings/*.yaml): what converters between formats are made of


@dataclass(frozen=True)
class Concept:
    """A shared battery quantity (pack voltage, state of charge...), in SI units.

    ``kind`` is ``number``, ``integer``, ``bool``, ``text``, ``list`` (of numbers), ``choice``
    (one of ``choices``) or ``flags`` (a set drawn from ``choices``); ``unit`` None when unitless.
    """

    name: str
    kind: str
    unit: Unit | None = None
    doc: str = ""
    choices: tuple[str, ...] = ()
    location: Location | None = None


@dataclass(frozen=True)
class FieldRef:
    """A field of a message (qualified name), or a concept (``message`` is ``"concepts"``)."""

    message: str
    field: str


class Direction(str, enum.Enum):
    """A direction of a reversible mapping: source -> target (forward) or back."""

    FORWARD = "forward"
    BACKWARD = "backward"


@dataclass(frozen=True)
class Rule:
    """One step of a mapping: ``op`` (a typed op of :mod:`codegen.ir.ops`, holding its parameters)
    computes ``targets`` from ``sources``; ``only`` limits it to one direction of a reversible mapping."""

    op: MappingOp
    targets: tuple[FieldRef, ...]
    sources: tuple[FieldRef, ...]
    doc: str = ""
    location: Location | None = None
    only: Direction | None = None


@dataclass(frozen=True)
class Endpoint:
    """What a converter reads or writes: one or more messages (the first required, the rest
    optional companions such as DroneCAN's BatteryInfoAux), each known by a short alias."""

    name: str
    messages: tuple[str, ...]
    aliases: tuple[str, ...]
    doc: str = ""
    location: Location | None = None


CONCEPTS_ENDPOINT = "concepts"  # the shared battery state every format maps to and from


@dataclass(frozen=True)
class Mapping:
    """How to turn the ``source`` endpoint into the ``target`` endpoint under ``policy``.

    ``reversible`` mappings are also generated target -> source; ``policy`` is ``strict``,
    ``px4`` or ``any``.
    """

    name: str
    source: str
    target: str
    policy: str
    rules: tuple[Rule, ...]
    reversible: bool = False
    doc: str = ""
    location: Location | None = None


@dataclass(frozen=True)
class MappingSet:
    """Everything one mapping file declares: concepts, endpoints and/or mappings."""

    file: str
    concepts: tuple[Concept, ...] = ()
    endpoints: tuple[Endpoint, ...] = ()
    mappings: tuple[Mapping, ...] = ()


# --------------------------------------------------------------------------------------------
# Cross-field rules (schemas/rules/*.yaml): what one message's fields must satisfy together


@dataclass(frozen=True)
class CrossFieldRule:
    """A rule relating fields of a message that its schema cannot state.

    ``exprs`` holds the expressions parsed (:mod:`codegen.ir.expr`), with loop variables resolved;
    the frontend has checked that the other names bind to each message in ``messages`` (see
    :func:`codegen.ir.rules.bind`). The text fields keep the expressions as written: the JSON form
    shows them, and a violation quotes the ``assert``. ``lines`` gives the source line of each key
    (``assert``, ``where``, ``for``, ``for[i]``, ``path``, ``message``).
    """

    id: str
    messages: tuple[str, ...]
    severity: str  # "error" or "warning" (advice)
    check: str  # the ``assert`` expression
    location: Location
    exprs: RuleExpressions = field(metadata={"json_form": False})  # the text fields, parsed
    doc: str = ""
    where: str | None = None
    loops: tuple[str, ...] = ()  # ``for`` clauses, "name in expression"
    path: str | None = None
    message: str = ""
    lines: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True)
class Schema:
    """Everything parsed from a set of sources: messages, and enums shared across messages."""

    messages: tuple[Message, ...] = ()
    enums: tuple[EnumDef, ...] = ()
    sources: tuple[str, ...] = field(default=())
    mappings: tuple[MappingSet, ...] = ()
    rules: tuple[CrossFieldRule, ...] = ()

    def message(self, qualified_name: str) -> Message:
        for m in self.messages:
            if m.qualified_name == qualified_name:
                return m
        raise KeyError(qualified_name)

    def enum(self, name: str) -> EnumDef:
        for e in self.enums:
            if e.name == name:
                return e
        for m in self.messages:
            for e in m.enums:
                if e.name == name:
                    return e
        raise KeyError(name)

    def merged(self, other: Schema) -> Schema:
        return Schema(
            messages=self.messages + other.messages,
            enums=self.enums + other.enums,
            sources=self.sources + other.sources,
            mappings=self.mappings + other.mappings,
            rules=self.rules + other.rules,
        )
