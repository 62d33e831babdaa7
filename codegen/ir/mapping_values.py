"""The values mapping ops take as parameters (:mod:`.ops`): numbers, units, named constants,
literals, and the typed entries of parameters a mapping file writes as a YAML mapping."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NewType

Number = int | float  # as the mapping file spells it: ``0`` stays an int, ``0.05`` a float; NaN is math.nan
UnitSymbol = NewType("UnitSymbol", str)  # a unit the unit registry knows (``mAh``, ``1``)


@dataclass(frozen=True)
class ConstantRef:
    """A constant named in a rule (``STATUS_FLAG_IN_USE``): a constant or enum entry of a message
    the rule reads or writes, or an entry of a schema-wide enum. Backends look its value up."""

    name: str

    @staticmethod
    def spelled(text: str) -> bool:
        """Whether a text parameter names a constant rather than being text: UPPER_CASE words."""
        return text.isupper() and text.replace("_", "").isalnum()


# A literal a rule writes or compares against: a number, a bool, text, or a named constant
Value = int | float | bool | str | ConstantRef


@dataclass(frozen=True)
class Entry:
    """An entry of a parameter written as a YAML mapping. The first field is the key; with one more
    field that field is the value (``lion: lithium-ion``), with more the value is a mapping of
    them (``STATUS_FLAG_IN_USE: {field: connected}``)."""


@dataclass(frozen=True)
class ChoiceValue(Entry):
    """``choice`` map: a choice of the concept and the format value standing for it."""

    choice: str
    value: Value


@dataclass(frozen=True)
class FlagBit(Entry):
    """``flags`` map: a choice of the flags concept and the bit (mask constant) standing for it."""

    choice: str
    mask: ConstantRef


@dataclass(frozen=True)
class ValuePair(Entry):
    """``enum_map`` map: a source field value and the target value it becomes."""

    source: Value
    target: Value


@dataclass(frozen=True)
class CellVoltage(Entry):
    """``dt_pack`` tables: a devicetree ``device-chemistry`` and one cell's voltage in volts."""

    chemistry: str
    volts: Number


@dataclass(frozen=True)
class BitSource(Entry):
    """``bits_from`` bits: the mask set when ``field`` of the source is true (or equals ``equals``)."""

    mask: ConstantRef
    field: str
    equals: Value | None = None
