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

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import BattgenError
from ...inputs.dispatch import read_records
from ...inputs.kinds import FLIGHT_LOG_KINDS, file_kind
from ...inputs.model import package_name
from ...inputs.records import Notice, Record, Unreadable
from ..battery.column_checks import FindingGroup, column_finding_groups, group_findings
from ..battery.columns import NDArray
from ..battery.figures import FlightFigures, flight_figures
from ..battery.view import Chunk, read_view
from ..convert import Conversion
from ..failsafe.logs import SampleTable
from ..messages import BATTERY_MESSAGES
from ..validate import Checker, Finding, make_checker

KELVIN = 273.15
COULOMB_PER_MAH = 3.6
INSTANCE_WORDS = {"ulog": "multi_id", "can": "node", "dataflash": "instance"}


@dataclass
class BatterySeries:
    """One battery of one input: its samples in SI (temperature in °C, charge in mAh, energy in Wh)."""

    source: str
    battery: int
    instance_word: str  # how the input names its instances: "multi_id", "node", "id"
    message: str
    time_source: str = "log"
    t: list[float] = field(default_factory=list)
    pack_voltage: list[float | None] = field(default_factory=list)
    current: list[float | None] = field(default_factory=list)
    state_of_charge: list[float | None] = field(default_factory=list)  # percent
    temperature: list[float | None] = field(default_factory=list)  # °C
    discharged: list[float | None] = field(default_factory=list)  # mAh
    remaining_energy: list[float | None] = field(default_factory=list)  # Wh
    cells: list[list[float]] = field(default_factory=list)  # known cell voltages of each sample
    # in the concepts' SI units, NaN unknown, for the flight figures (codegen.apps.battery.figures)
    charge_c: list[float] = field(default_factory=list)  # the discharged counter
    energy_j: list[float] = field(default_factory=list)  # the consumed-energy counter
    armed: list[float] = field(default_factory=list)  # 1.0 / 0.0 / NaN
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
    def power(self) -> list[float | None]:
        return [
            v * i if v is not None and i is not None else None
            for v, i in zip(self.pack_voltage, self.current, strict=True)
        ]

    def flight(self) -> FlightFigures:
        """The flight's figures, by the one definition the fleet views share."""

        def array(values: list[float | None]) -> NDArray:
            return np.array([np.nan if v is None else v for v in values], np.float64)

        return flight_figures(
            np.array(self.t, np.float64),
            array(self.pack_voltage),
            array(self.current),
            np.array(self.charge_c, np.float64),
            np.array(self.energy_j, np.float64),
            np.array(self.armed, np.float64) if self.knows_arming else None,
        )

    @property
    def cell_count(self) -> int:
        return max((len(c) for c in self.cells), default=0)

    def cell(self, k: int) -> list[float | None]:
        return [c[k] if k < len(c) else None for c in self.cells]

    @property
    def imbalance(self) -> list[float | None]:
        """max - min cell voltage of each sample with at least two known cells."""
        return [max(c) - min(c) if len(c) >= 2 else None for c in self.cells]


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
    path: Path, schema_dir: Path, *, message: str | None = None, kind: str | None = None, display: str | None = None
) -> InputSeries:
    """Every battery of one input as series, with the validator's findings. Raises a BattgenError (a
    LocatedError naming file and line for a damaged input) when the input cannot be read at all.

    A flight log or capture (every kind the battery view reads) gives its series from the view, the reading
    ``export`` and ``failsafe`` share (:mod:`codegen.apps.battery.view`), with the samples for the failsafe
    replay (:attr:`InputSeries.samples`); its records are also validated one by one where its kind has a message
    schema (DataFlash has none). Other inputs (JSON, YAML) go record by record through the converters."""
    name = display or path.as_posix()
    kind = kind or file_kind(path)
    if kind in FLIGHT_LOG_KINDS and message is None:
        return _view_input(path, name, schema_dir, kind)
    return _record_input(path, schema_dir, name, message, kind)


def _view_input(path: Path, name: str, schema_dir: Path, kind: str) -> InputSeries:
    batteries: dict[int, BatterySeries] = {}
    table = SampleTable()
    messages: list[str] = []
    records = 0
    word = INSTANCE_WORDS.get(kind, "id")
    checkable = kind == "ulog"  # the kinds whose findings come from the view's columns (column_checks)
    chunks: list[Chunk] = []
    for chunk in read_view(path, name, all_fields=checkable):
        if checkable:
            chunks.append(chunk)
        table.add(chunk)
        records += chunk.n
        if chunk.batch.message not in messages:
            messages.append(chunk.batch.message)
        numbers = chunk.battery
        for number in sorted(set(numbers.tolist())):
            rows = np.nonzero(numbers == number)[0]
            series = batteries.get(number)
            if series is None:
                series = batteries[number] = BatterySeries(name, number, word, chunk.batch.message)
            _extend(series, chunk, rows)
    for series in batteries.values():
        _order(series)
    out = InputSeries(
        name, ", ".join(messages) or "none", [batteries[k] for k in sorted(batteries)], [], [], [], records
    )
    out.samples = table
    if kind == "dataflash":  # a DataFlash log has no message schema: nothing to validate
        return out
    column = None
    if checkable:
        _, checker = make_checker(schema_dir, default_message(path, kind), [str(path)], kind)
        column = column_finding_groups(path, name, kind, chunks, checker)
    if column is not None:
        out.findings, out.notices, out.unreadable = column
    else:  # the view's batches of this kind lack the records' places (a tlog's frames): read them one by one
        checked = _record_input(path, schema_dir, name, None, kind)
        out.findings, out.notices, out.unreadable = checked.findings, checked.notices, checked.unreadable
    return out


def _numbers(chunk: Chunk, concept: str, rows: NDArray, scale: float = 1.0, offset: float = 0.0) -> list[float | None]:
    values = chunk.number(concept)[rows] * scale + offset
    return [None if v != v else v for v in values.tolist()]


def _extend(series: BatterySeries, chunk: Chunk, rows: NDArray) -> None:
    """Append a chunk's rows of one battery, in the units the page shows."""
    series.t.extend(np.asarray(chunk.batch.t, np.float64)[rows].tolist())
    series.pack_voltage.extend(_numbers(chunk, "pack_voltage", rows))
    series.current.extend(_numbers(chunk, "current", rows))
    series.state_of_charge.extend(_numbers(chunk, "state_of_charge", rows, 100.0))
    series.temperature.extend(_numbers(chunk, "temperature", rows, 1.0, -KELVIN))
    series.discharged.extend(_numbers(chunk, "discharged", rows, 1 / COULOMB_PER_MAH))
    series.remaining_energy.extend(_numbers(chunk, "remaining_energy", rows, 1 / 3600.0))
    series.charge_c.extend(chunk.number("discharged")[rows].tolist())
    series.energy_j.extend(chunk.number("consumed_energy")[rows].tolist())
    armed = chunk.batch.armed
    if armed is not None:
        series.knows_arming = True
        series.armed.extend(np.asarray(armed, np.float64)[rows].tolist())
    else:
        series.armed.extend([math.nan] * len(rows))
    cells = chunk.concepts["cell_voltages"]
    matrix = np.asarray(cells.values[rows], np.float64)
    if matrix.ndim == 2 and matrix.shape[1]:
        widths = cells.lengths[rows] if cells.lengths is not None else np.zeros(len(rows), np.int64)
        beyond = np.arange(matrix.shape[1])[None, :] >= np.where(cells.valid[rows], widths, 0)[:, None]
        with np.errstate(invalid="ignore"):
            matrix[beyond | ~(matrix > 0.0)] = np.nan  # a cell past the count, unknown (NaN) or not positive
        series.cells.extend([v for v in row if v == v] for row in matrix.tolist())
    else:
        series.cells.extend([] for _ in range(len(rows)))
    health = chunk.number("state_of_health")[rows]
    if (health > 0).any():
        series.state_of_health = float(health[health > 0][-1]) * 100.0
    cycles = chunk.concepts["cycle_count"]
    known_cycles = [int(v) for v, ok in zip(cycles.values[rows], cycles.valid[rows], strict=True) if ok and v > 0]
    if known_cycles:
        series.cycle_count = known_cycles[-1]
    serial = chunk.concepts["serial_number"]
    if not series.serial:
        for v, ok in zip(serial.values[rows].tolist(), serial.valid[rows].tolist(), strict=True):
            text = str(v) if ok and not isinstance(v, str) and v else v if ok and isinstance(v, str) else ""
            if text.strip("\x00 0"):
                series.serial = text
                break


def _order(series: BatterySeries) -> None:
    """A battery's samples in time order (a ULog's batteries come instance by instance, chunks in order)."""
    t = np.array(series.t, np.float64)
    if not len(t) or bool((t[1:] >= t[:-1]).all()):
        return  # in order already (one instance, its chunks read in order)
    order = np.argsort(t, kind="stable").tolist()  # a record without a time (NaN) last
    for name in (
        "t",
        "pack_voltage",
        "current",
        "state_of_charge",
        "temperature",
        "discharged",
        "charge_c",
        "energy_j",
        "armed",
    ):
        values = getattr(series, name)
        setattr(series, name, [values[k] for k in order])
    series.remaining_energy = [series.remaining_energy[k] for k in order]
    series.cells = [series.cells[k] for k in order]


def _record_input(path: Path, schema_dir: Path, name: str, message: str | None, kind: str | None) -> InputSeries:
    msg, checker = make_checker(schema_dir, message or default_message(path, kind), [str(path)], kind)
    conversion = Conversion(_package_of(checker), msg.qualified_name, "concepts", "strict")
    batteries: dict[int, BatterySeries] = {}
    out = InputSeries(name, msg.qualified_name, [], [], [], [], 0)
    t0: float | None = None
    found: list[tuple[float, int, Finding]] = []
    for item in read_records(path, msg, name, model=checker.cls, kind=kind):
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
        series = batteries.get(number)
        if series is None:
            series = batteries[number] = BatterySeries(name, number, word, msg.qualified_name, source)
        _append(series, (t or 0.0) - (t0 or 0.0), state)
        for finding in checker.check(item):
            found.append(((t or 0.0) - (t0 or 0.0), number, finding))
    out.batteries = [batteries[k] for k in sorted(batteries)]
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
)


def _state(conversion: Conversion, record: Record) -> Mapping[str, Any] | None:
    """The concepts the report draws, read off the converter's state (not its whole ``to_dict``)."""
    try:
        objs = conversion.source.build(record)
        state = conversion.func(*objs, policy="strict", report=conversion.module.LossReport())
    except (BattgenError, ValueError, TypeError, AttributeError):  # ConversionError is a ValueError
        return None
    return {name: getattr(state, name, None) for name in _CONCEPTS}


def _append(series: BatterySeries, t: float, state: Mapping[str, Any]) -> None:
    series.t.append(t)
    series.pack_voltage.append(_number(state.get("pack_voltage")))
    series.current.append(_number(state.get("current")))
    soc = _number(state.get("state_of_charge"))
    series.state_of_charge.append(None if soc is None else soc * 100.0)
    kelvin = _number(state.get("temperature"))
    series.temperature.append(None if kelvin is None else kelvin - KELVIN)
    charge = _number(state.get("discharged"))
    series.discharged.append(None if charge is None else charge / COULOMB_PER_MAH)
    series.charge_c.append(math.nan if charge is None else charge)
    consumed = _number(state.get("consumed_energy"))
    series.energy_j.append(math.nan if consumed is None else consumed)
    series.armed.append(math.nan)  # a data file carries no arming state
    energy = _number(state.get("remaining_energy"))
    series.remaining_energy.append(None if energy is None else energy / 3600.0)
    cells = state.get("cell_voltages") or []
    series.cells.append([v for v in (_number(c) for c in cells) if v is not None and v > 0.0])
    health = _number(state.get("state_of_health"))
    if health is not None and health > 0:
        series.state_of_health = health * 100.0
    cycles = state.get("cycle_count")
    if isinstance(cycles, int) and not isinstance(cycles, bool) and cycles > 0:
        series.cycle_count = cycles
    serial = state.get("serial_number")
    if isinstance(serial, int) and not isinstance(serial, bool) and serial > 0:
        serial = str(serial)  # the concept is an integer (DroneCAN model_instance_id, PX4's uint16)
    if isinstance(serial, str) and serial.strip("\x00 0") and not series.serial:
        series.serial = serial
