"""Real flights as failsafe samples: PX4 ULog (.ulg), MAVLink telemetry logs (.tlog), DataFlash (.bin).

Each reader yields :class:`~.stream.Sample`\\ s in time order (seconds from the log's first record),
one per battery reading, every battery instance of the log (1-based, as ArduPilot prints it), with
the arming state last logged before it (disarmed before the first). The files are read by the
inputs layer: ``.ulg`` and ``.tlog`` by :mod:`codegen.inputs.flight_logs` (battery_status and
vehicle_status; BATTERY_STATUS or SYS_STATUS and the autopilot's HEARTBEAT), ``.bin`` by
:mod:`codegen.inputs.dataflash` (``BAT`` records, ``ARM``/``EV`` arming; the log's own ``PARM``
records are its parameters, :func:`bin_parameters`).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import cast

from ...inputs import dataflash, flight_logs
from ...inputs.flight_logs import FlightArming, FlightReading
from ...inputs.model import UlogRuntime
from ..package import bundled_package, package_module
from .reading import BatteryReading
from .stream import Sample

LOG_KINDS = ("ulog", "tlog", "bin")


def log_kind(path: Path) -> str | None:
    """``ulog`` / ``tlog`` / ``bin`` from the content where it tells (ULog and DataFlash magic
    bytes), else from the extension; None for anything else (a JSON Lines stream)."""
    try:
        with path.open("rb") as f:
            head = f.read(8)
    except OSError:
        return None
    if head.startswith(b"ULog\x01\x12\x35"):
        return "ulog"
    if head.startswith(dataflash.HEAD + bytes([dataflash.FMT_TYPE])):
        return "bin"
    suffix = path.suffix.lower()
    return {".ulg": "ulog", ".tlog": "tlog", ".bin": "bin"}.get(suffix)


def read_log(path: Path, kind: str) -> Iterator[Sample]:
    if kind == "ulog":
        return ulog_samples(path)
    if kind == "tlog":
        return tlog_samples(path)
    return bin_samples(path)


def bin_parameters(path: Path) -> dict[str, float]:
    """The parameters a DataFlash log recorded (PARM; a value set again in flight: its last)."""
    return dataflash.log_parameters(dataflash.open_log(path))


def bin_samples(path: Path) -> Iterator[Sample]:
    log = dataflash.open_log(path)
    armed = False
    for item in dataflash.flight_records(log):
        if isinstance(item, dataflash.ArmingRecord):
            armed = item.armed
            continue
        reading = BatteryReading(item.voltage_v, item.current_a, item.consumed_mah)
        where = f"offset {item.offset}"
        yield Sample(0, item.time_s, armed, reading, None, None, {}, item.instance + 1, where, round(item.time_s * 1e6))


def _samples(records: Iterator[FlightReading | FlightArming]) -> Iterator[Sample]:
    """Samples of a log's readings, each with the arming state last logged before it."""
    armed = False
    for rec in records:
        if isinstance(rec, FlightArming):
            armed = rec.armed
            continue
        reading = BatteryReading(rec.voltage_v, rec.current_a, rec.consumed_mah)
        yield Sample(0, rec.time_s, armed, reading, None, None, {}, rec.instance + 1, rec.where, rec.clock_us)


def ulog_samples(path: Path) -> Iterator[Sample]:
    runtime = cast(UlogRuntime, package_module(bundled_package(), "_ulog"))
    return _samples(flight_logs.ulog_readings(path, runtime))


def tlog_samples(path: Path) -> Iterator[Sample]:
    return _samples(flight_logs.tlog_readings(path))
