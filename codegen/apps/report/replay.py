"""The failsafe replay shown in a report: the same evaluator as ``battgen failsafe``, on the same samples.

Parameters come from ``--params`` (a .param/.params file), else from an ArduPilot log's own (a DataFlash log's PARM
records, a tlog's PARAM_VALUE frames); the
vehicle from ``--vehicle``, else detected from the parameters (:func:`~..failsafe.vehicles.detect_vehicle`).
A flight log or capture is replayed from the samples of the battery view the report's series come from (the same
samples ``battgen failsafe`` replays, so the markers are exactly its events, on the same clock: seconds since the
log's start); a log without an arming state is taken as armed throughout (said on the page). Other inputs (JSON
Lines records) are replayed from the report's series, taken as armed throughout.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ...errors import BattgenError
from ..failsafe.columnar import replay_table
from ..failsafe.evaluator import BatteryFailsafe, Event, make_failsafe
from ..failsafe.logs import NO_ARMING_NOTE, own_parameters
from ..failsafe.px4_log import read_px4_log
from ..failsafe.px4_replay import replay_px4
from ..failsafe.reading import BatteryReading
from ..failsafe.settings import battery_settings
from ..failsafe.stream import Sample, read_parameter_values
from ..failsafe.vehicles import detect_vehicle
from .page import FailsafeEvent, Replay
from .series import InputSeries

NO_PARAMS = "no failsafe parameters: give --params FILE (BATT_* values) to replay the failsafe"
# A PX4 log without --params: replayed through PX4's own failsafe (_px4); where that cannot read the log, this says so.
PX4_NOT_REPLAYED = (
    "PX4's failsafe is not replayed here: the firmware's own warning levels (battery_status.warning) are marked "
    "on the plots; give --params FILE with BATT_* values to replay ArduPilot's"
)


def _series_samples(item: InputSeries) -> Iterator[Sample]:
    """Samples from the report's series, in time order across batteries (armed throughout)."""
    rows = []
    for s in item.batteries:
        columns = (s.t.tolist(), s.pack_voltage.tolist(), s.current.tolist(), s.discharged.tolist())
        for t, volts, amps, used in zip(*columns, strict=True):
            reading = BatteryReading(_known(volts), amps if amps == amps and amps >= 0 else None, _known(used))
            rows.append((t, s.battery + 1, reading))
    rows.sort(key=lambda r: (r[0], r[1]))
    for k, (t, instance, reading) in enumerate(rows):
        yield Sample(k + 1, t, True, reading, None, None, {}, instance, f"sample {k + 1}")


def _known(value: float) -> float | None:
    return None if value != value else value


def replay(item: InputSeries, path: Path, params: Path | None, vehicle: str | None) -> Replay:
    """The failsafe events of every battery of one input, on the report's time axis."""
    own = own_parameters(item.samples) if params is None and item.samples is not None else None
    if params is not None:
        values, where = read_parameter_values(params), str(params)
    elif own is not None:
        context = item.samples.context if item.samples is not None else None
        values, where = own, f"the log's {context.parameters_from if context is not None else 'parameters'}"
    elif item.context is not None and item.context.autopilot == "px4":
        return _px4(path, item)
    else:
        return Replay(note=NO_PARAMS)
    try:
        detection = detect_vehicle(values, vehicle)
        failsafe = make_failsafe(battery_settings(values, detection.vehicle), detection.vehicle)
    except ValueError as exc:
        raise BattgenError(f"{where}: {exc}") from None
    replay_table(failsafe, item.samples) if item.samples is not None else _run(failsafe, _series_samples(item))
    note = f"replayed with {where}; vehicle {detection.how}"
    if item.samples is None or not item.samples.has_arming:
        note += "; " + NO_ARMING_NOTE
    thresholds = {
        s.instance - 1: {"BATT_LOW_VOLT": s.low_volt, "BATT_CRT_VOLT": s.crt_volt} for s in failsafe.settings.values()
    }
    events = [FailsafeEvent(e.time, e.battery - 1, e.level.name, _text(e)) for e in failsafe.events]
    return Replay(events, note, thresholds)


def _px4(path: Path, item: InputSeries) -> Replay:
    """A PX4 log replayed through PX4's own battery failsafe (:mod:`..failsafe.px4_replay`) with the log's
    parameters: its warning levels and commander's actions, at their times."""
    try:
        replayed = replay_px4(read_px4_log(path))
    except ValueError as exc:  # a log without what PX4's replay reads
        return Replay(note=f"{PX4_NOT_REPLAYED} ({exc})")
    events = [
        FailsafeEvent(e.time, e.battery - 1, e.label, f"{e.action_name} -> {e.outcome}: \u201c{e.text}\u201d")
        for e in replayed.events
    ]
    note = "; ".join(
        ["replayed through PX4's battery failsafe with the log's own BAT_*/COM_* parameters", *replayed.notes]
    )
    return Replay(events, note)  # its thresholds are charges, drawn on the state of charge (log_facts), not volts


def _run(failsafe: BatteryFailsafe, samples: Iterator[Sample]) -> None:
    """Feed every sample."""
    for sample in samples:
        try:
            failsafe.update(sample.t, sample.battery, armed=sample.armed, instance=sample.instance, **sample.extra)
        except ValueError as exc:
            raise BattgenError(f"{sample.place}: {exc}") from None


def _text(e: Event) -> str:
    """The action and what happened, then ArduPilot's own STATUSTEXT."""
    ran = f"{e.action} -> {e.outcome}" if e.executed else f"{e.action}: not run (a higher-priority action already ran)"
    return f"{e.cause} {ran}: \u201c{e.ardupilot_text}\u201d"
