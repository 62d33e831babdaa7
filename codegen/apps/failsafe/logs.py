"""Real flights as failsafe samples: PX4 ULog (.ulg), MAVLink telemetry logs (.tlog), DataFlash (.bin).

Each reader yields :class:`~.stream.Sample`\\ s in time order (seconds from the log's first record),
one per battery reading, every battery instance of the log (1-based, as ArduPilot prints it):

- ``.ulg``: ``battery_status`` of every multi_id (instance = multi_id + 1; ``voltage_v``,
  ``current_a``, ``discharged_mah``) and the arming state from ``vehicle_status.arming_state``
  (2 = ARMED), read as columns through the generated ULog reader.
- ``.tlog``: ``BATTERY_STATUS`` (instance = ``id`` + 1; the valid cell voltages summed,
  ``current_battery`` cA, ``current_consumed`` mAh) or, in a log without it, ``SYS_STATUS``
  (``voltage_battery`` mV, ``current_battery`` cA) as battery 1; armed from the autopilot's
  ``HEARTBEAT`` (``base_mode`` bit 128, MAV_MODE_FLAG_SAFETY_ARMED), read through pymavlink.
- ``.bin``: ``BAT`` records and ``ARM``/``EV`` arming, through :mod:`codegen.inputs.dataflash`;
  the log's own ``PARM`` records are its parameters (:func:`bin_parameters`).

A reading before the first arming state is taken as disarmed.
"""

from __future__ import annotations

import contextlib
import heapq
import io
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ...errors import BattgenError
from ...inputs import dataflash
from ...inputs.dataflash import shortest_float32
from ...inputs.records import InputError
from ..package import bundled_package, package_module
from .reading import BatteryReading
from .stream import Sample

UINT16_MAX = 65535
MAV_MODE_FLAG_SAFETY_ARMED = 128
MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
PX4_ARMING_STATE_ARMED = 2
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


def _number(value: Any) -> float | None:
    """A logged float32 as its shortest decimal (so 16.2 V equals a 16.2 V parameter); None if unknown."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return shortest_float32(float(value)) if isinstance(value, float) else float(value)


def ulog_samples(path: Path) -> Iterator[Sample]:
    ulog = package_module(bundled_package(), "_ulog")
    display = path.as_posix()
    try:
        log = ulog.read(str(path), warn=False)
    except (OSError, ValueError) as exc:
        raise InputError(display, 0, f"expected a ULog file: {exc}") from None
    with log:
        topics = log.topics()
        streams: list[list[tuple[int, int, Any]]] = []  # lists, not generators: multi_id binds now
        for topic, multi_id in topics:
            if topic == "vehicle_status":
                cols = log.columns(topic, multi_id, use_numpy=False)
                states = cols.get("arming_state", [])
                armed_rows = zip(cols["timestamp"], states, strict=False)
                streams.append([(int(ts), 0, a == PX4_ARMING_STATE_ARMED) for ts, a in armed_rows])
            elif topic == "battery_status":
                cols = log.columns(topic, multi_id, use_numpy=False)
                volts = cols.get("voltage_v") or cols.get("voltage_filtered_v") or []
                current = cols.get("current_a") or [None] * len(volts)
                used = cols.get("discharged_mah") or [None] * len(volts)
                rows = zip(cols["timestamp"], volts, current, used, strict=False)
                streams.append([(int(ts), 1, (multi_id, v, a, m)) for ts, v, a, m in rows])
        if not any(topic == "battery_status" for topic, _ in topics):
            raise BattgenError(f"{display}: expected battery_status records in the log")
        start: int | None = None
        armed = False
        for ts, kind, value in heapq.merge(*streams, key=lambda r: (r[0], r[1])):
            start = ts if start is None else start
            if kind == 0:
                armed = value
                continue
            mid, v, a, m = value
            volts, current, used = _number(v), _number(a), _number(m)
            reading = BatteryReading(
                volts if volts and volts > 0 else None,
                current if current is not None and current >= 0 else None,
                used if used is not None and used >= 0 else None,
            )
            t = (ts - start) / 1e6
            yield Sample(0, t, armed, reading, None, None, {}, mid + 1, f"battery_status multi_id {mid}", ts)


def _mavlink_reading(msg: Any) -> tuple[int, BatteryReading]:
    if msg.get_type() == "SYS_STATUS":
        volts = None if msg.voltage_battery in (UINT16_MAX, 0) else msg.voltage_battery / 1000.0
        current = None if msg.current_battery < 0 else msg.current_battery / 100.0
        return 1, BatteryReading(volts, current)
    cells = [v for v in list(msg.voltages) + list(getattr(msg, "voltages_ext", []) or []) if v not in (UINT16_MAX, 0)]
    volts = sum(cells) / 1000.0 if cells else None
    current = None if msg.current_battery < 0 else msg.current_battery / 100.0
    used = None if msg.current_consumed < 0 else float(msg.current_consumed)
    return int(msg.id) + 1, BatteryReading(volts, current, used)


def tlog_samples(path: Path) -> Iterator[Sample]:
    from pymavlink import mavutil

    display = path.as_posix()
    types = ["HEARTBEAT", "BATTERY_STATUS", "SYS_STATUS"]

    def connect() -> Any:
        with contextlib.redirect_stdout(io.StringIO()):
            try:
                return mavutil.mavlink_connection(str(path), notimestamps=False, dialect="common")
            except OSError as exc:
                raise InputError(display, 0, f"cannot read file: {exc.strerror or exc}") from None

    conn = connect()
    has_battery_status = conn.recv_match(type="BATTERY_STATUS") is not None
    conn.close()
    conn = connect()
    start: float | None = None
    armed = False
    index = 0
    try:
        while True:
            with contextlib.redirect_stdout(io.StringIO()):
                msg = conn.recv_match(type=types)
            if msg is None:
                return
            index += 1
            stamp = float(getattr(msg, "_timestamp", 0.0))
            start = stamp if start is None else start
            name = msg.get_type()
            if name == "HEARTBEAT":
                if msg.type != MAV_TYPE_GCS and msg.autopilot != MAV_AUTOPILOT_INVALID:
                    armed = bool(msg.base_mode & MAV_MODE_FLAG_SAFETY_ARMED)
                continue
            if (name == "SYS_STATUS") == has_battery_status:
                continue
            instance, reading = _mavlink_reading(msg)
            t = round((stamp - start) * 1e6) / 1e6  # whole microseconds, as the log stores them
            where = f"{name} message {index}"
            yield Sample(0, t, armed, reading, None, None, {}, instance, where, round(stamp * 1e6))
    finally:
        conn.close()
