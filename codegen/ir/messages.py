"""Messages, and the facts only one format has (PX4 struct layout, DroneCAN signature, MAVLink CRC_EXTRA...)."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from .basics import Location, SourceFormat
from .fields import Constant, EnumDef, Field


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


class CyphalKind(str, enum.Enum):
    MESSAGE = "message"
    REQUEST = "request"
    RESPONSE = "response"


@dataclass(frozen=True)
class CyphalInfo:
    """A Cyphal v1 data type as pydsdl reads it. Bit lengths are the object's own (a delimited type's
    32-bit delimiter header, written where it is nested in another type, is not counted); ``extent`` is
    in bits and equals ``max_bitlen`` for a sealed type. ``full_name`` is the name as the source spells
    it (``reg.drone.service.battery.Status`` for the older namespace); ``alias_of`` then names the
    ``reg.udral`` type it is read as, whose name the message's qualified name carries."""

    full_name: str
    major: int
    minor: int
    kind: CyphalKind
    union: bool
    sealed: bool
    extent: int
    min_bitlen: int
    max_bitlen: int
    fixed_port_id: int | None = None
    deprecated: bool = False
    union_tag_bits: int = 0
    alias_of: str | None = None


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
class PdefInfo:
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
    params: PdefInfo | None = None
    cyphal: CyphalInfo | None = None

    @property
    def is_union(self) -> bool:
        """A DSDL union (DroneCAN ``@union``, Cyphal ``@union``): exactly one field is held at a time."""
        return (self.dronecan is not None and self.dronecan.union) or (self.cyphal is not None and self.cyphal.union)

    def field(self, name: str) -> Field:
        for f in self.fields:
            if f.name == name:
                return f
        raise KeyError(name)
