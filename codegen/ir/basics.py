"""The IR's roots: which format a definition came from, where it stands, and units of measure."""

from __future__ import annotations

import enum
from dataclasses import dataclass


class SourceFormat(str, enum.Enum):
    UORB = "uorb"
    DRONECAN = "dronecan"
    DEVICETREE = "devicetree"
    MAVLINK = "mavlink"
    PDEF = "params"  # ArduPilot parameter metadata (apm.pdef.xml); the value names the schema folder and prefix
    CYPHAL = "cyphal"  # Cyphal (UAVCAN v1) DSDL, read through pydsdl


@dataclass(frozen=True)
class Location:
    """Where a definition came from: the file as given to the frontend and a 1-based line."""

    file: str
    line: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


@dataclass(frozen=True)
class SchemaWarning:
    """Something a schema says that battgen accepts but that upstream's own tools flag (a linter
    warning): printed as ``file:line: warning: ...`` and never a failure. ``kind`` names the class
    of warning (for counting and filtering), ``message`` what is wrong and how it was read."""

    location: Location
    kind: str
    message: str

    def __str__(self) -> str:
        return f"{self.location}: warning: {self.message}"


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
