"""Battery time series from any log, capture or data file battgen reads, one per battery instance.

Every record is read by the data readers (:func:`codegen.inputs.dispatch.read_records`), checked by the
message's generated validator (the findings go into the report) and turned into the shared battery concepts by
the generated converters, so a PX4 ULog, a MAVLink tlog, a DroneCAN capture and a JSON Lines file all give the
same SI columns. Unknown values (every sentinel) are ``None``, which the plots draw as gaps.

Which battery a record belongs to: the ULog ``multi_id``, the CAN node, else the message's own battery index
(MAVLink ``id``). Time: seconds since the first record of the file, from the log's timestamps (ULog, tlog, CAN)
or the record's ``timestamp`` field (microseconds, as uORB and the JSON forms of it carry); without either, the
record's position (one per second) -- said in the series' ``time_source``.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import BattgenError
from ...frontends.loader import RULES_DIR
from ...inputs.dispatch import read_records
from ...inputs.files.kinds import FLIGHT_LOG_KINDS, file_kind
from ...inputs.model import package_name
from ...inputs.records import Notice, Record, Unreadable
from ..battery.can_batches import UDRAL
from ..battery.catalog import bundled_catalog
from ..battery.column_checks import FindingGroup, column_finding_groups, group_findings
from ..battery.columns import ConceptColumn, NDArray
from ..battery.context import LogContext
from ..battery.figures import FlightFigures, flight_figures
from ..battery.view import Chunk, read_view
from ..conversion.convert import Conversion
from ..failsafe.logs import SampleTable
from ..gate.selection import Names, Settings, names_of
from ..gate.validate import Checker, Finding, make_checker
from ..schemas.messages import BATTERY_MESSAGES
from ..schemas.package import bundled_schemas

KELVIN = 273.15
COULOMB_PER_MAH = 3.6
INSTANCE_WORDS = {"ulog": "multi_id", "can": "node", "dataflash": "instance"}


# the series of one battery, each a float64 array with NaN where unknown: name -> (concept, scale, offset)
SERIES = {
    "pack_voltage": ("pack_voltage", 1.0, 0.0),
    "current": ("current", 1.0, 0.0),
    "state_of_charge": ("state_of_charge", 100.0, 0.0),  # percent
    "temperature": ("temperature", 1.0, -KELVIN),  # °C
    "discharged": ("discharged", 1 / COULOMB_PER_MAH, 0.0),  # mAh
    "remaining_energy": ("remaining_energy", 1 / 3600.0, 0.0),  # Wh
    "charge_c": ("discharged", 1.0, 0.0),  # the discharged counter in C, for the flight figures
    "energy_j": ("consumed_energy", 1.0, 0.0),  # the consumed-energy counter in J
    "warning": ("warning", 1.0, 0.0),  # the firmware's own warning level: a code into warning_levels()
}


def warning_levels() -> tuple[str, ...]:
    """The warning concept's choices (schemas/mappings/concepts.yaml), which the view's codes index; a data file's
    records carry the choice by name and are coded by this order too."""
    return bundled_catalog().concept("warning").choices


@dataclass
class BatterySeries:
    """One battery of one input: its samples as float64 arrays in time order, NaN where unknown (temperature in
    °C, charge in mAh, energy in Wh; ``charge_c``/``energy_j`` in SI for the flight figures), and ``cells`` a
    matrix of a column per cell (NaN: a cell the sample does not give)."""

    source: str
    battery: int
    instance_word: str  # how the input names its instances: "multi_id", "node", "id"
    message: str
    time_source: str = "log"
    t: NDArray = field(default_factory=lambda: np.zeros(0))
    pack_voltage: NDArray = field(default_factory=lambda: np.zeros(0))
    current: NDArray = field(default_factory=lambda: np.zeros(0))
    state_of_charge: NDArray = field(default_factory=lambda: np.zeros(0))
    temperature: NDArray = field(default_factory=lambda: np.zeros(0))
    discharged: NDArray = field(default_factory=lambda: np.zeros(0))
    remaining_energy: NDArray = field(default_factory=lambda: np.zeros(0))
    cells: NDArray = field(default_factory=lambda: np.zeros((0, 0)))
    charge_c: NDArray = field(default_factory=lambda: np.zeros(0))
    energy_j: NDArray = field(default_factory=lambda: np.zeros(0))
    warning: NDArray = field(default_factory=lambda: np.zeros(0))  # codes into warning_levels(), NaN unknown
    armed: NDArray = field(default_factory=lambda: np.zeros(0))  # 1.0 / 0.0 / NaN
    knows_arming: bool = False  # whether the input carries an arming state at all
    serial: str = ""
    cycle_count: int | None = None  # the last the battery reported
    state_of_health: float | None = None  # percent, the last the battery reported

    @property
    def label(self) -> str:
        if self.instance_word == "node":  # a DroneCAN battery is known by its node id
            return f"node {self.battery}"
        return f"battery {self.battery + 1} ({self.instance_word} {self.battery})"

    @property
    def power(self) -> NDArray:
        return np.asarray(self.pack_voltage * self.current, np.float64)

    def flight(self) -> FlightFigures:
        """The flight's figures, by the one definition the fleet views share."""
        return flight_figures(
            self.t,
            self.pack_voltage,
            self.current,
            self.charge_c,
            self.energy_j,
            self.armed if self.knows_arming else None,
        )

    @functools.cached_property
    def cell_count(self) -> int:
        """The cells some sample gives (the last column holding a value, counted from 1)."""
        return _given_width(self.cells)

    def cell(self, k: int) -> NDArray:
        return np.asarray(self.cells[:, k], np.float64)

    @property
    def has_cell_data(self) -> bool:
        """Whether the cells are measured: the one rule the page's figures and plots and the fleet table follow."""
        return not self.cells_split_evenly

    @functools.cached_property
    def cells_split_evenly(self) -> bool:
        """Whether the cells are no measurement: every sample's known cells equal to each other and the pack voltage
        a whole number of them, at least as many as are given (PX4's battery library fills the cells with the pack
        voltage over its cell count when the driver measures none; a 12-cell pack in a 10-cell array: the first 10)."""
        if not self.cell_count:
            return False
        rows = ~np.isnan(self.cells[:, : self.cell_count]).any(axis=1) & ~np.isnan(self.pack_voltage)
        if not rows.any():
            return False
        cells = self.cells[rows, : self.cell_count]
        even = bool((np.ptp(cells, axis=1) < 1e-4).all())
        pack, cell = self.pack_voltage[rows], cells[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            count = np.round(pack / cell)
        return even and bool(
            ((count >= self.cell_count) & (np.abs(count * cell - pack) <= 0.01 * np.abs(pack) + 1e-3)).all()
        )

    @functools.cached_property
    def imbalance(self) -> NDArray:
        """max - min cell voltage of each sample with at least two known cells (else NaN)."""
        if not self.cells.size:
            return np.full(len(self.t), np.nan)
        known = (~np.isnan(self.cells)).sum(axis=1)
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN row: NaN, as wanted
            spread = np.nanmax(self.cells, axis=1) - np.nanmin(self.cells, axis=1)
        return np.asarray(np.where(known >= 2, spread, np.nan), np.float64)


@dataclass
class InputSeries:
    """What one input gave: its batteries, its validation findings and notices, what could not be read."""

    source: str
    message: str
    batteries: list[BatterySeries]
    findings: list[FindingGroup]  # the validator's findings, grouped per battery, rule, path and severity
    notices: list[Notice]
    unreadable: list[Unreadable]
    records: int
    not_converted: int = 0
    samples: SampleTable | None = None  # the failsafe's samples of a log read through the battery view
    names: Names | None = None  # what the gate's selectors may name: the checked message's rules and fields
    left_out: dict[str, int] = field(default_factory=dict)  # findings the gate left out: why -> how many
    gate: Settings | None = None  # the gate's settings in force for this input (the firmware's profile applied)

    @property
    def context(self) -> LogContext | None:
        """What the log says about itself (None: a data file)."""
        return self.samples.context if self.samples is not None else None


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def _time(record: Record, index: int) -> tuple[float | None, str]:
    loc: Mapping[str, object] = record.location or {}
    t = loc.get("t")
    if isinstance(t, int | float):
        return float(t), "log"
    stamp = loc.get("timestamp_us")
    if isinstance(stamp, int):
        return stamp / 1e6, "log"
    data = record.instance.to_dict() if record.instance is not None else record.data
    if isinstance(data, Mapping):
        value = data.get("timestamp")
        if isinstance(value, int) and not isinstance(value, bool) and value > 0:
            return value / 1e6, "field"
    return float(index), "position"


def _battery(record: Record, state: Mapping[str, Any]) -> tuple[int, str]:
    loc: Mapping[str, object] = record.location or {}
    for key, word in (("multi_id", "multi_id"), ("node", "node")):
        value = loc.get(key)
        if isinstance(value, int):
            return value, word
    index = state.get("battery_index")
    return (index if isinstance(index, int) else 0), "id"


def default_message(path: Path, kind: str | None) -> str:
    message = BATTERY_MESSAGES.get(kind or file_kind(path))
    if message is None:
        raise BattgenError(f"{path}: give --message for this input (e.g. uorb.BatteryStatus)")
    return message


def read_input(
    path: Path,
    schema_dir: Path,
    *,
    message: str | None = None,
    kind: str | None = None,
    display: str | None = None,
    subjects: Sequence[str] = (),
) -> InputSeries:
    """Every battery of one input as series, with the validator's findings. Raises a BattgenError (a
    LocatedError naming file and line for a damaged input) when the input cannot be read at all.

    A flight log or capture (every kind the battery view reads) gives its series from the view, the reading
    ``export`` and ``failsafe`` share (:mod:`codegen.apps.battery.view`), with the samples for the failsafe
    replay (:attr:`InputSeries.samples`); its records are also validated one by one where its kind has a message
    schema (DataFlash has none). Other inputs (JSON, YAML) go record by record through the converters.
    ``subjects``: the ``--cyphal-subject`` pairs a CAN capture's Cyphal subjects are read with, as ``export`` reads
    them (its UDRAL batteries' records are then checked as the energy source's type)."""
    name = display or path.as_posix()
    kind = kind or file_kind(path)
    if kind in FLIGHT_LOG_KINDS and message is None:
        return _view_input(path, name, schema_dir, kind, subjects)
    return _record_input(path, schema_dir, name, message, kind)


def _view_input(path: Path, name: str, schema_dir: Path, kind: str, subjects: Sequence[str] = ()) -> InputSeries:
    batteries: dict[int, _Parts] = {}
    table = SampleTable()
    messages: list[str] = []
    records = 0
    word = INSTANCE_WORDS.get(kind, "id")
    checkable = kind == "ulog"  # the kinds whose findings come from the view's columns (column_checks)
    chunks: list[Chunk] = []
    for chunk in read_view(path, name, all_fields=checkable, subjects=subjects):
        if checkable:
            chunks.append(chunk)
        table.add(chunk)
        records += chunk.n
        if chunk.batch.message not in messages:
            messages.append(chunk.batch.message)
        numbers = chunk.battery
        for number in sorted(set(numbers.tolist())):
            rows = np.nonzero(numbers == number)[0]
            parts = batteries.get(number)
            if parts is None:
                parts = batteries[number] = _Parts(BatterySeries(name, number, word, chunk.batch.message))
            parts.extend(chunk, rows)
    out = InputSeries(
        name, ", ".join(messages) or "none", [batteries[k].finish() for k in sorted(batteries)], [], [], [], records
    )
    out.samples = table
    if kind == "dataflash":  # a DataFlash log has no message schema: nothing to validate
        return out
    column = None
    if checkable:
        message = default_message(path, kind)
        # the bundled folder: its message's format and the rules are all the checker reads (not pydsdl's Cyphal)
        only = (message.partition(".")[0], RULES_DIR) if schema_dir == bundled_schemas() else None
        _, checker = make_checker(schema_dir, message, [str(path)], kind, only=only)
        out.names = names_of(checker.message, checker.rules, checker.extra is not None)
        column = column_finding_groups(path, name, kind, chunks, checker)
    if column is not None:
        out.findings, out.notices, out.unreadable = column
    else:  # the view's batches of this kind lack the records' places (a tlog's frames): read them one by one
        # a capture whose UDRAL batteries were read: their energy source's transfers are the records checked
        udral = UDRAL[0] if subjects and UDRAL[0] in messages else None
        checked = _record_input(path, schema_dir, name, udral, kind, subjects)
        out.findings, out.notices, out.unreadable = checked.findings, checked.notices, checked.unreadable
        out.names = checked.names
    return out


def _given_width(cells: NDArray) -> int:
    """The columns of a cell matrix up to the last that holds a value."""
    if not cells.size:
        return 0
    given = np.flatnonzero(~np.isnan(cells).all(axis=0))
    return int(given[-1]) + 1 if len(given) else 0


def _first_serial(serial: ConceptColumn, rows: NDArray) -> str:
    """The first serial number the rows give ("": none): an integer that is not 0, or a text that is not blank,
    NULs or zeros. Each distinct value is judged once (a battery repeats its serial in every record)."""
    values, valid = serial.values[rows], serial.valid[rows]
    if values.dtype != object:
        given = np.flatnonzero(valid & (values != 0))
        return str(values[given[0]]) if len(given) else ""
    for v in dict.fromkeys(values[valid].tolist()):  # in the order they first appear
        text = v if isinstance(v, str) else str(v) if v else ""
        if text.strip("\x00 0"):
            return text
    return ""


class _Parts:
    """A battery's series as the chunks give them, joined and put in time order at the end."""

    def __init__(self, series: BatterySeries) -> None:
        self.series = series
        self.parts: dict[str, list[NDArray]] = {name: [] for name in ("t", "armed", "cells", *SERIES)}

    def extend(self, chunk: Chunk, rows: NDArray) -> None:
        """A chunk's rows of this battery, in the units the page shows."""
        s, parts = self.series, self.parts
        parts["t"].append(np.asarray(chunk.batch.t, np.float64)[rows])
        for name, (concept, scale, offset) in SERIES.items():
            parts[name].append(chunk.number(concept)[rows] * scale + offset)
        armed = chunk.batch.armed
        if armed is not None:
            s.knows_arming = True
        parts["armed"].append(np.full(len(rows), np.nan) if armed is None else np.asarray(armed, np.float64)[rows])
        cells = chunk.concepts["cell_voltages"]
        matrix = np.asarray(cells.values[rows], np.float64).reshape(len(rows), -1)
        if matrix.shape[1]:
            widths = cells.lengths[rows] if cells.lengths is not None else np.zeros(len(rows), np.int64)
            beyond = np.arange(matrix.shape[1])[None, :] >= np.where(cells.valid[rows], widths, 0)[:, None]
            with np.errstate(invalid="ignore"):
                matrix[beyond | ~(matrix > 0.0)] = np.nan  # past the count, unknown or not positive: no cell
        parts["cells"].append(matrix)
        health = chunk.number("state_of_health")[rows]
        if (health > 0).any():
            s.state_of_health = float(health[health > 0][-1]) * 100.0
        cycles = chunk.concepts["cycle_count"]
        reported = cycles.values[rows][cycles.valid[rows] & (cycles.values[rows] > 0)]
        if len(reported):
            s.cycle_count = int(reported[-1])
        if not s.serial:
            s.serial = _first_serial(chunk.concepts["serial_number"], rows)

    def finish(self) -> BatterySeries:
        """The series joined, in time order (a record without a time last)."""
        s, parts = self.series, self.parts
        for name in ("t", "armed", *SERIES):
            setattr(s, name, np.concatenate(parts[name]) if parts[name] else np.zeros(0))
        widths = [_given_width(m) for m in parts["cells"]]  # a format's 14 slots, of which a pack fills its cells
        s.cells = np.full((len(s.t), max(widths, default=0)), np.nan)
        at = 0
        for m, width in zip(parts["cells"], widths, strict=True):
            s.cells[at : at + len(m), :width] = m[:, :width]
            at += len(m)
        if len(s.t) and not bool((s.t[1:] >= s.t[:-1]).all()):  # a ULog's instances, or its chunks, out of order
            order = np.argsort(s.t, kind="stable")
            for name in ("t", "armed", *SERIES):
                setattr(s, name, getattr(s, name)[order])
            s.cells = s.cells[order]
        return s


def _record_input(
    path: Path, schema_dir: Path, name: str, message: str | None, kind: str | None, subjects: Sequence[str] = ()
) -> InputSeries:
    msg, checker = make_checker(schema_dir, message or default_message(path, kind), [str(path)], kind)
    conversion = Conversion(_package_of(checker), msg.qualified_name, "concepts", "strict")
    batteries: dict[int, _Records] = {}
    out = InputSeries(name, msg.qualified_name, [], [], [], [], 0)
    out.names = names_of(msg, checker.rules, checker.extra is not None)
    t0: float | None = None
    found: list[tuple[float, int, Finding]] = []
    for item in read_records(path, msg, name, model=checker.cls, kind=kind, subjects=subjects):
        if isinstance(item, Notice):
            out.notices.append(item)
            continue
        if isinstance(item, Unreadable):
            out.unreadable.append(item)
            continue
        out.records += 1
        t, source = _time(item, out.records - 1)
        t0 = t if t0 is None else t0
        state = _state(conversion, item)
        if state is None:
            out.not_converted += 1
            continue
        number, word = _battery(item, state)
        records = batteries.get(number)
        if records is None:
            records = batteries[number] = _Records(BatterySeries(name, number, word, msg.qualified_name, source))
        records.append((t or 0.0) - (t0 or 0.0), state)
        for finding in checker.check(item):
            found.append(((t or 0.0) - (t0 or 0.0), number, finding))
    out.batteries = [batteries[k].finish() for k in sorted(batteries)]
    out.findings = group_findings(found)
    return out


def _package_of(checker: Checker) -> str:
    return package_name(checker.cls)


_CONCEPTS = (
    "pack_voltage",
    "current",
    "state_of_charge",
    "temperature",
    "discharged",
    "consumed_energy",
    "remaining_energy",
    "cell_voltages",
    "state_of_health",
    "cycle_count",
    "serial_number",
    "battery_index",
    "warning",
)


def _state(conversion: Conversion, record: Record) -> Mapping[str, Any] | None:
    """The concepts the report draws, read off the converter's state (not its whole ``to_dict``)."""
    try:
        objs = conversion.source.build(record)
        state = conversion.func(*objs, policy="strict", report=conversion.module.LossReport())
    except (BattgenError, ValueError, TypeError, AttributeError):  # ConversionError is a ValueError
        return None
    return {name: getattr(state, name, None) for name in _CONCEPTS}


class _Records:
    """A battery's series gathered record by record (a data file: in file order), as arrays at the end."""

    def __init__(self, series: BatterySeries) -> None:
        self.series = series
        self.rows: dict[str, list[float]] = {name: [] for name in ("t", "armed", *SERIES)}
        self.cells: list[list[float]] = []

    def append(self, t: float, state: Mapping[str, Any]) -> None:
        s, rows = self.series, self.rows
        rows["t"].append(t)
        for name, (concept, scale, offset) in SERIES.items():
            value = _number(state.get(concept))
            rows[name].append(math.nan if value is None else value * scale + offset)
        rows["armed"].append(math.nan)  # a data file carries no arming state
        level, levels = state.get("warning"), warning_levels()
        rows["warning"][-1] = float(levels.index(level)) if level in levels else math.nan
        cells = state.get("cell_voltages") or []
        self.cells.append([v if v is not None and v > 0.0 else math.nan for v in (_number(c) for c in cells)])
        health = _number(state.get("state_of_health"))
        if health is not None and health > 0:
            s.state_of_health = health * 100.0
        cycles = state.get("cycle_count")
        if isinstance(cycles, int) and not isinstance(cycles, bool) and cycles > 0:
            s.cycle_count = cycles
        serial = state.get("serial_number")
        if isinstance(serial, int) and not isinstance(serial, bool) and serial > 0:
            serial = str(serial)  # the concept is an integer (DroneCAN model_instance_id, PX4's uint16)
        if isinstance(serial, str) and serial.strip("\x00 0") and not s.serial:
            s.serial = serial

    def finish(self) -> BatterySeries:
        s = self.series
        for name, values in self.rows.items():
            setattr(s, name, np.array(values, np.float64))
        s.cells = np.full((len(self.cells), max((len(c) for c in self.cells), default=0)), np.nan)
        for k, row in enumerate(self.cells):
            s.cells[k, : len(row)] = row
        return s
