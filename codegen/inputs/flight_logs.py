"""PX4 ULog (.ulg) and MAVLink telemetry (.tlog) flight logs as battery readings and arming states, in
time order: what :mod:`.dataflash` gives for ArduPilot's .bin logs, for the failsafe replays.

- ``.ulg``: ``battery_status`` of every multi_id (``voltage_v``, or ``voltage_filtered_v`` in old
  logs; ``current_a``; ``discharged_mah``) and the arming state from ``vehicle_status.arming_state``
  (2 = ARMED), read as columns through the generated ULog reader; a logged float32 is its shortest
  decimal (so 16.2 V equals a 16.2 V parameter). PX4 logs 0 V and negative currents and charges
  when it does not measure them: those are None.
- ``.tlog``: ``BATTERY_STATUS`` (the valid cell voltages summed, ``current_battery`` cA,
  ``current_consumed`` mAh) or, in a log without it, ``SYS_STATUS`` (``voltage_battery`` mV,
  ``current_battery`` cA) as battery 0; armed from the autopilot's ``HEARTBEAT`` (``base_mode``
  bit 128, MAV_MODE_FLAG_SAFETY_ARMED; a ground station's or an invalid autopilot's heartbeat says
  nothing of the vehicle), read through pymavlink.

Times are seconds from the log's first record read; ``clock_us`` is the log's own clock (ULog:
microseconds since boot; tlog: microseconds since the Unix epoch). Instances are 0-based.
"""

from __future__ import annotations

import contextlib
import heapq
import io
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import BattgenError
from .dataflash import shortest_float32
from .model import UlogRuntime
from .records import InputError

UINT16_MAX = 65535
MAV_MODE_FLAG_SAFETY_ARMED = 128
MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
PX4_ARMING_STATE_ARMED = 2


@dataclass(frozen=True)
class FlightReading:
    """One battery reading; a value the log does not give (or marks as not measured) is None."""

    time_s: float
    clock_us: int
    instance: int
    voltage_v: float | None
    current_a: float | None
    consumed_mah: float | None
    where: str


@dataclass(frozen=True)
class FlightArming:
    time_s: float
    armed: bool


def _number(value: Any) -> float | None:
    """A logged float32 as its shortest decimal; None if unknown."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return shortest_float32(float(value)) if isinstance(value, float) else float(value)


def ulog_readings(path: Path, runtime: UlogRuntime) -> Iterator[FlightReading | FlightArming]:
    """Every battery_status reading and vehicle_status arming state of a ULog file, in time order."""
    display = path.as_posix()
    try:
        log = runtime.read(str(path), warn=False)
    except (OSError, ValueError) as exc:
        raise InputError(display, 0, f"expected a ULog file: {exc}") from None
    try:
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
        for ts, kind, value in heapq.merge(*streams, key=lambda r: (r[0], r[1])):
            start = ts if start is None else start
            t = (ts - start) / 1e6
            if kind == 0:
                yield FlightArming(t, value)
                continue
            mid, v, a, m = value
            volts, amps, mah = _number(v), _number(a), _number(m)
            yield FlightReading(
                t,
                ts,
                mid,
                volts if volts and volts > 0 else None,
                amps if amps is not None and amps >= 0 else None,
                mah if mah is not None and mah >= 0 else None,
                f"battery_status multi_id {mid}",
            )
    finally:
        log.close()


def _mavlink_reading(msg: Any) -> tuple[int, float | None, float | None, float | None]:
    """(0-based instance, volts, amps, mAh) of a BATTERY_STATUS or SYS_STATUS message."""
    if msg.get_type() == "SYS_STATUS":
        volts = None if msg.voltage_battery in (UINT16_MAX, 0) else msg.voltage_battery / 1000.0
        current = None if msg.current_battery < 0 else msg.current_battery / 100.0
        return 0, volts, current, None
    cells = [v for v in list(msg.voltages) + list(getattr(msg, "voltages_ext", []) or []) if v not in (UINT16_MAX, 0)]
    volts = sum(cells) / 1000.0 if cells else None
    current = None if msg.current_battery < 0 else msg.current_battery / 100.0
    used = None if msg.current_consumed < 0 else float(msg.current_consumed)
    return int(msg.id), volts, current, used


def tlog_readings(path: Path) -> Iterator[FlightReading | FlightArming]:
    """The battery readings (BATTERY_STATUS, else SYS_STATUS) and the autopilot's arming state of a .tlog."""
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
            t = round((stamp - start) * 1e6) / 1e6  # whole microseconds, as the log stores them
            name = msg.get_type()
            if name == "HEARTBEAT":
                if msg.type != MAV_TYPE_GCS and msg.autopilot != MAV_AUTOPILOT_INVALID:
                    yield FlightArming(t, bool(msg.base_mode & MAV_MODE_FLAG_SAFETY_ARMED))
                continue
            if (name == "SYS_STATUS") == has_battery_status:
                continue
            instance, volts, amps, mah = _mavlink_reading(msg)
            yield FlightReading(t, round(stamp * 1e6), instance, volts, amps, mah, f"{name} message {index}")
    finally:
        conn.close()
