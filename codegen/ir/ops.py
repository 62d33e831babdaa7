"""Mapping ops: what one rule of a converter mapping (``schemas/mappings/*.yaml``) computes.

Each op is a frozen dataclass whose fields are the rule's parameters, typed (numbers, names of
fields, units and constants, tuples of typed entries: :mod:`.mapping_values`); its ``NAME`` is
the ``op:`` a mapping file writes, and ``SOURCES`` / ``TARGETS`` say how many ``from`` / ``to``
references it takes. The fields and their annotations are the single description of an op: the
mappings frontend parses rules and builds the per-op JSON Schema from them, the IR's JSON form
writes them back (:mod:`.mapping_json`), and :mod:`.mapping_visitor` is the contract a backend
implements, one method per op.

Field names are the parameter keys of the mapping files. A parameter a rule leaves out is
``None`` (or ``()`` / ``False``); each docstring says what that means.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import ClassVar, get_args

from .mapping_values import (
    BitSource,
    CellVoltage,
    ChoiceValue,
    ConstantRef,
    FlagBit,
    Number,
    UnitSymbol,
    Value,
    ValuePair,
)

# (least, most) references a rule of an op takes in ``from`` or ``to``; most None: no limit
Arity = tuple[int, int | None]
ONE: Arity = (1, 1)
NONE: Arity = (0, 0)
ONE_OR_MORE: Arity = (1, None)


class Op:
    """The common base of the mapping ops (see the module docstring)."""

    NAME: ClassVar[str]
    SOURCES: ClassVar[Arity] = ONE
    TARGETS: ClassVar[Arity] = ONE
    # whether a rule still applies when an optional companion message it reads is absent
    # (rules of other ops are skipped then)
    HANDLES_MISSING: ClassVar[bool] = False


class PX4Conversion(str, enum.Enum):
    RAW = "raw"  # the number as it is (C float assignment)
    UNITS = "units"  # multiplied (or divided) by the factor between the units


class PX4Form(str, enum.Enum):
    MULTIPLY = "multiply"  # x * factor
    DIVIDE = "divide"  # x / (1 / factor), as C code that divides by 100.0f does


# ---------------------------------------------------------------------------------------------
# A format field <-> a concept (strict mappings); ``from`` is the format's, ``to`` the concept's


@dataclass(frozen=True)
class Scale(Op):
    """A number, converted between the field's and the concept's units.

    Reading, the field's sentinel or any of ``unknown`` means unknown, and so does a value not
    above ``valid_above`` or above ``valid_max``; a devicetree list gives its first element.
    Writing, unknown becomes the first marker and a value is stored as the field holds it
    (float16, rounded and clamped integers, at most ``valid_max``). ``unit`` is the field's unit
    where its schema names none (a DSDL comment in prose); ``negate`` when the field counts the
    other way from the concept (CBAT reports a discharge as a negative current).
    """

    NAME: ClassVar[str] = "scale"
    unknown: tuple[Number, ...] = ()
    valid_above: Number | None = None
    valid_max: Number | None = None
    unit: UnitSymbol | None = None
    negate: bool = False


@dataclass(frozen=True)
class Copy(Op):
    """A value as it is (integers, bools, text), plus ``add`` reading and minus it writing.

    The field's sentinel or any of ``unknown`` reads as unknown; unknown writes the first marker.
    """

    NAME: ClassVar[str] = "copy"
    add: Number | None = None
    unknown: tuple[Number, ...] = ()


@dataclass(frozen=True)
class Const(Op):
    """``to`` is set to ``value`` (no ``from``); several targets all get it."""

    NAME: ClassVar[str] = "const"
    SOURCES: ClassVar[Arity] = NONE
    TARGETS: ClassVar[Arity] = ONE_OR_MORE
    value: Value | None


@dataclass(frozen=True)
class SocHybrid(Op):
    """State of charge from ``from: [remaining, full, percent]``: remaining over full (energy, or charge as
    UDRAL's Status suggests) when both are known and positive, else the percent (``unknown`` markers, at
    most ``valid_max``); without a percent (UDRAL has none), unknown then."""

    NAME: ClassVar[str] = "soc_hybrid"
    SOURCES: ClassVar[Arity] = (2, 3)
    unknown: tuple[Number, ...] = ()
    valid_max: Number | None = None


@dataclass(frozen=True)
class Flag(Op):
    """A bool concept: whether the bit ``mask`` of the field is set."""

    NAME: ClassVar[str] = "flag"
    mask: ConstantRef


@dataclass(frozen=True)
class FlagChoice(Op):
    """One choice (``value``) of a choice concept, standing for the bit ``mask`` of the field."""

    NAME: ClassVar[str] = "flag_choice"
    mask: ConstantRef
    value: str


@dataclass(frozen=True)
class Flags(Op):
    """A flags concept: each choice in ``map`` stands for one bit of the field."""

    NAME: ClassVar[str] = "flags"
    map: tuple[FlagBit, ...]


@dataclass(frozen=True)
class Choice(Op):
    """A choice concept: each choice in ``map`` stands for one value of the field; ``unknown`` is
    the value meaning unknown (not reported as dropped reading, written for unknown)."""

    NAME: ClassVar[str] = "choice"
    map: tuple[ChoiceValue, ...]
    unknown: Value | None = None


@dataclass(frozen=True)
class ValueFlags(Op):
    """A flags concept from a field that holds one condition at a time (UDRAL's ``Error``): each choice in
    ``map`` stands for one value of the field, ``none`` is the value of no condition. Other values have no
    counterpart (reported dropped). Written back, the first choice of ``map`` that is set wins (the map lists
    the most severe first) and the others are reported dropped; no choice set writes ``none``."""

    NAME: ClassVar[str] = "value_flags"
    map: tuple[ChoiceValue, ...]
    none: Value | None = None


@dataclass(frozen=True)
class Cells(Op):
    """A list of numbers (cell voltages) in an array field, converted between units. ``count_field``
    (of the same message) holds how many are valid; without it, a per-element sentinel ends the list."""

    NAME: ClassVar[str] = "cells"
    count_field: str | None = None


@dataclass(frozen=True)
class MavlinkVoltages(Op):
    """MAVLink's ``from: [voltages, voltages_ext]`` <-> ``to: [pack voltage, cell voltages]``: cells
    1-10 then 11-14, or the pack voltage spilled over cells in UINT16_MAX - 1 chunks."""

    NAME: ClassVar[str] = "mavlink_voltages"
    SOURCES: ClassVar[Arity] = (2, 2)
    TARGETS: ClassVar[Arity] = (2, 2)


# ---------------------------------------------------------------------------------------------
# Devicetree facts -> concepts


@dataclass(frozen=True)
class DtPack(Op):
    """``from: [voltage max design, voltage min design, chemistry]`` -> ``to: [cell count, nominal
    voltage]``: cells from the design voltages over the chemistry's charged (else empty) cell
    voltage, nominal voltage from the cells and the chemistry's nominal cell voltage."""

    NAME: ClassVar[str] = "dt_pack"
    SOURCES: ClassVar[Arity] = (3, 3)
    TARGETS: ClassVar[Arity] = (2, 2)
    cell_charged_v: tuple[CellVoltage, ...]
    cell_empty_v: tuple[CellVoltage, ...]
    cell_nominal_v: tuple[CellVoltage, ...]


@dataclass(frozen=True)
class OcvSoc(Op):
    """State of charge from ``from: [OCV table temperatures, OCV tables]`` and two converter inputs
    (keyword arguments named ``voltage_input`` and ``temperature_input``), as Linux computes it."""

    NAME: ClassVar[str] = "ocv_soc"
    SOURCES: ClassVar[Arity] = (2, 2)
    voltage_input: str
    temperature_input: str


# ---------------------------------------------------------------------------------------------
# Whole messages


@dataclass(frozen=True)
class SameNames(Op):
    """Every field the two messages (``from``, ``to``: message aliases) share by name, copied."""

    NAME: ClassVar[str] = "same_names"


@dataclass(frozen=True)
class ZeroAll(Op):
    """Every field of the target messages (``to``) that has a sentinel starts at zero, as a C
    struct initialised with ``{}`` does."""

    NAME: ClassVar[str] = "zero_all"
    SOURCES: ClassVar[Arity] = NONE
    TARGETS: ClassVar[Arity] = ONE_OR_MORE


# ---------------------------------------------------------------------------------------------
# PX4's own code paths (px4 mappings between formats), in float32 arithmetic


@dataclass(frozen=True)
class PX4Convert(Op):
    """A number as PX4's C code converts it: read as a C float, ``convert`` by the unit factor
    (``source_unit`` / ``target_unit`` override the fields' units; ``form`` multiplies or divides),
    ``round`` (roundf), stored as the target's C type (then DroneCAN saturation), at least
    ``at_least``. When ``guard`` (a source field) is false, the value is not ``finite`` or not
    above ``above``, the target gets ``otherwise`` (0 if not given) instead."""

    NAME: ClassVar[str] = "px4_convert"
    convert: PX4Conversion
    form: PX4Form | None = None
    source_unit: UnitSymbol | None = None
    target_unit: UnitSymbol | None = None
    round: bool = False
    guard: str | None = None
    finite: bool = False
    at_least: Number | None = None
    above: Number | None = None
    otherwise: Value | None = None


@dataclass(frozen=True)
class PX4Int(Op):
    """An integer as C assigns it: (source & ``mask``) + ``add``, wrapped to the target's C type."""

    NAME: ClassVar[str] = "px4_int"
    mask: ConstantRef | None = None
    add: Number | None = None


@dataclass(frozen=True)
class PX4Warning(Op):
    """uORB's warning level from the target field ``of`` (state of charge, 0-1) and three
    thresholds: EMERGENCY below ``emergency``, CRITICAL below ``critical``, LOW below ``low``."""

    NAME: ClassVar[str] = "px4_warning"
    SOURCES: ClassVar[Arity] = NONE
    of: str
    emergency: Number
    critical: Number
    low: Number


@dataclass(frozen=True)
class EnumMap(Op):
    """A C ``switch``: each source value in ``map`` becomes its target value, others ``default`` (0
    if not given)."""

    NAME: ClassVar[str] = "enum_map"
    map: tuple[ValuePair, ...]
    default: Value | None = None


@dataclass(frozen=True)
class BitsFrom(Op):
    """A bitmask built from source fields (``from`` lists them): each entry of ``bits`` sets its mask."""

    NAME: ClassVar[str] = "bits_from"
    SOURCES: ClassVar[Arity] = ONE_OR_MORE
    bits: tuple[BitSource, ...]


@dataclass(frozen=True)
class PX4StreamCells(Op):
    """PX4's MAVLink stream: ``from: [voltage, cells, cell count, connected]`` -> ``to: [voltages,
    voltages_ext]``; cells below ``cell_threshold`` volts (0.0001 if not given) mean none."""

    NAME: ClassVar[str] = "px4_stream_cells"
    SOURCES: ClassVar[Arity] = (4, 4)
    TARGETS: ClassVar[Arity] = (2, 2)
    cell_threshold: Number | None = None


@dataclass(frozen=True)
class PX4ReceiverCells(Op):
    """PX4's MAVLink receiver: ``from: voltages`` -> ``to: [cells, cell count, pack voltage]``."""

    NAME: ClassVar[str] = "px4_receiver_cells"
    TARGETS: ClassVar[Arity] = (3, 3)


@dataclass(frozen=True)
class PX4BridgeCells(Op):
    """PX4's uavcan bridge: ``from: [voltage, aux cells]`` -> ``to: [cells, cell count]``; without the
    companion message (BatteryInfoAux) one cell holding the pack voltage."""

    NAME: ClassVar[str] = "px4_bridge_cells"
    SOURCES: ClassVar[Arity] = (2, 2)
    TARGETS: ClassVar[Arity] = (2, 2)
    HANDLES_MISSING: ClassVar[bool] = True


@dataclass(frozen=True)
class PX4CellList(Op):
    """PX4's uavcannode: ``from: [cells, cell count]`` -> a list of that many cells."""

    NAME: ClassVar[str] = "px4_cell_list"
    SOURCES: ClassVar[Arity] = (2, 2)


@dataclass(frozen=True)
class PX4AuxCapacity(Op):
    """``from: [full energy (Wh), nominal voltage]`` -> capacity: energy over voltage in the target's
    unit, when the voltage is above ``above`` (FLT_EPSILON if not given)."""

    NAME: ClassVar[str] = "px4_aux_capacity"
    SOURCES: ClassVar[Arity] = (2, 2)
    above: Number | None = None


@dataclass(frozen=True)
class PX4UdralEnergy(Op):
    """PX4's Cyphal battery subscriber (``Subscribers/udral/Battery.hpp``) on ``from: [energy, full energy,
    nominal voltage]`` -> ``to: [remaining, discharged]``, in float32: remaining = energy / full energy,
    unchecked (NaN or infinity as C divides); discharged = (full - energy) / (nominal voltage * 3600), which
    is ampere-hours stored as the target's number unconverted, computed even when the nominal voltage is
    NaN (PX4 tests ``!= NAN``, always true) or no Parameters message came (NaN then). The three are read in
    joules and volts, as UDRAL gives them."""

    NAME: ClassVar[str] = "px4_udral_energy"
    SOURCES: ClassVar[Arity] = (3, 3)
    TARGETS: ClassVar[Arity] = (2, 2)
    HANDLES_MISSING: ClassVar[bool] = True


@dataclass(frozen=True)
class PX4BridgeEstimates(Op):
    """PX4's uavcan bridge with its Battery object: ``from: [current, a field of the companion message]``
    -> ``to: [discharged charge, time remaining, average current]``, reading the target's fields
    ``soc_of`` (state of charge, 0-1) and ``capacity_of`` (mAh).

    Without the companion message (raw mode) the discharged charge grows by |current| over the
    converter input ``dt_input`` (seconds since the previous message, at most 2) from the input
    ``discharged_input`` (the total so far, 0 if not given), and the time remaining is NaN. With it
    (BatteryInfoAux) the discharged charge stays as given, the average current is the Battery
    object's filter, which a disarmed vehicle holds at ``average_current`` (BAT_AVRG_CURRENT), and
    the time remaining is state of charge times capacity over that current, NaN without a capacity.
    """

    NAME: ClassVar[str] = "px4_bridge_estimates"
    SOURCES: ClassVar[Arity] = (2, 2)
    TARGETS: ClassVar[Arity] = (3, 3)
    HANDLES_MISSING: ClassVar[bool] = True
    soc_of: str
    capacity_of: str
    average_current: Number
    dt_input: str
    discharged_input: str


@dataclass(frozen=True)
class ArduPilotTemperature(Op):
    """ArduPilot's DroneCAN battery monitor and its BATTERY_STATUS: a temperature in kelvin taken only
    when it is a number above 0 (``update_interim_state``), sent as ``(int16_t)((K - 273.15f) * 100)``
    centidegrees, else INT16_MAX (``send_battery_status``: no temperature)."""

    NAME: ClassVar[str] = "ardupilot_temperature"


@dataclass(frozen=True)
class ArduPilotCurrent(Op):
    """ArduPilot's current: the message's current times the converter input ``curr_mult_input``
    (BATT_CURR_MULT, 1 if not given), sent as ``constrain_float(amps * 100, -INT16_MAX, INT16_MAX)``
    centiamperes (AP_Math's constrain turns NaN into the middle of the range: 0)."""

    NAME: ClassVar[str] = "ardupilot_current"
    curr_mult_input: str


@dataclass(frozen=True)
class ArduPilotCells(Op):
    """ArduPilot's cell voltages in BATTERY_STATUS: ``from: [pack voltage, aux cells]`` -> ``to:
    [voltages, voltages_ext]``. Without the companion message (no cell voltages) the pack voltage in
    mV is spread over the ten cells, at most UINT16_MAX - 1 each, UINT16_MAX once less than 0.001 mV
    is left, and no extended cells; with it the first ``max_cells`` cells in mV (float to uint16), the
    rest 0, each raised by an equal share of what the pack voltage exceeds their sum."""

    NAME: ClassVar[str] = "ardupilot_cells"
    SOURCES: ClassVar[Arity] = (2, 2)
    TARGETS: ClassVar[Arity] = (2, 2)
    HANDLES_MISSING: ClassVar[bool] = True
    max_cells: Number


@dataclass(frozen=True)
class ArduPilotEstimates(Op):
    """ArduPilot's consumed charge and energy, remaining percentage and time for a DroneCAN battery:
    ``from: [voltage, current, state of charge %, remaining Wh, full Wh, aux nominal voltage]`` -> ``to:
    [consumed mAh, consumed hJ, remaining %, time remaining s]``, all in float32 as AP_BattMonitor holds
    them. The charge and energy so far come in as the converter inputs ``consumed_input`` (mAh) and
    ``energy_input`` (Wh), the seconds since the previous message as ``dt_input`` (none: the first
    message), BATT_CAPACITY as ``capacity_input`` (mAh, ``capacity_default`` if not given),
    BATT_OPTIONS as ``options_input`` and BATT_CURR_MULT as ``curr_mult_input``.

    The battery's state of charge is used unless BATT_OPTIONS bit 0 (ignore it) is set or it is 127
    (unknown); otherwise the percentage comes from the capacity and the charge consumed, which grows by
    the current over the time since the previous message (under 2 s) whenever no companion message
    came or the state of charge is not used. A companion message with a nominal voltage above 0 sets
    the consumed charge and energy from the full and remaining energy, and the time remaining."""

    NAME: ClassVar[str] = "ardupilot_estimates"
    SOURCES: ClassVar[Arity] = (6, 6)
    TARGETS: ClassVar[Arity] = (4, 4)
    HANDLES_MISSING: ClassVar[bool] = True
    dt_input: str
    consumed_input: str
    energy_input: str
    capacity_input: str
    options_input: str
    curr_mult_input: str
    capacity_default: Number


MappingOp = (
    Scale
    | Copy
    | Const
    | SocHybrid
    | Flag
    | FlagChoice
    | Flags
    | Choice
    | ValueFlags
    | Cells
    | MavlinkVoltages
    | DtPack
    | OcvSoc
    | SameNames
    | ZeroAll
    | PX4Convert
    | PX4Int
    | PX4Warning
    | EnumMap
    | BitsFrom
    | PX4StreamCells
    | PX4ReceiverCells
    | PX4BridgeCells
    | PX4CellList
    | PX4AuxCapacity
    | PX4BridgeEstimates
    | PX4UdralEnergy
    | ArduPilotTemperature
    | ArduPilotCurrent
    | ArduPilotCells
    | ArduPilotEstimates
)

# every op by the name mapping files give it, in the order above
OPS: dict[str, type[MappingOp]] = {cls.NAME: cls for cls in get_args(MappingOp)}
