"""ArduPilot DataFlash logs (``.bin``, and text ``.log`` through :mod:`.dataflash_text`), read through
pymavlink's DataFlash readers (``DFReader_binary``, ``DFReader_text``).

A DataFlash log is a sequence of messages, each ``0xA3 0x95 <type>`` and a payload laid out by the
log's own ``FMT`` records (the FMT record of type 128 describes FMT itself). pymavlink's reader
parses them; this module asks it for the messages a caller wants and hands them out as plain
:class:`DataflashMessage` records (type, index, byte offset, ``TimeUS``, fields), plus three views
the battery tools need:

- :func:`log_parameters`: the log's ``PARM`` records (``Name``, ``Value``); a parameter logged
  more than once (set in flight) takes its last value, as the vehicle ended up with it.
- :func:`battery_records`: ``BAT`` records (``Inst`` 0-based, ``Volt``, ``Curr``, ``CurrTot`` mAh,
  ``RemPct``), and the older layouts (``BAT`` without ``Inst``, ``BAT2``..``BAT9`` per monitor,
  ``CURR``/``CURR2``/``CUR2`` before ArduPilot 3.6), in V / A / mAh (:mod:`.dataflash_units`).
- :func:`arming_records`: the arming state from ``ARM`` records (``ArmState``) and the ``EV``
  events older logs carry (the rule, with ``LOG_DISARMED``, in :mod:`.dataflash_arming`).

pymavlink prints what it skips (garbage, unknown types) on stdout/stderr; that text is captured and
counted instead (:attr:`DataflashLog.skipped_notes`). A file that is not a DataFlash log, or holds
no message, is an :class:`~.records.InputError` naming the file. The reader maps the file, so
memory stays flat; every loop ends at the end of the file.
"""

from __future__ import annotations

import contextlib
import functools
import io
import math
import os
import re
import struct
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...errors import cannot_read
from ..records import InputError
from .arming import event_state
from .text import HEAD_BYTES, is_text_dataflash, open_text_reader
from .units import field_scales

HEAD = b"\xa3\x95"
FMT_TYPE = 0x80
# BAT (Inst/Instance from 3.6 on), BAT2..BAT9 and CURR/CURR2/CUR2 of older firmware, one type per monitor
NUMBERED_TYPES = {f"BAT{n}": n - 1 for n in range(2, 10)} | {"CURR2": 1, "CUR2": 1}
BATTERY_TYPES = frozenset({"BAT", "BATT", "CURR"} | set(NUMBERED_TYPES))
ARMING_TYPES = frozenset({"ARM", "EV"})
# ArduPilot's start-up MSG naming the board and its unique id: "Pixhawk4 0047002B 34385105 36363539"
BOARD_ID = re.compile(r"(\S+) [0-9A-F]{8} [0-9A-F]{8} [0-9A-F]{8}")


@dataclass(frozen=True)
class DataflashMessage:
    """One message of the log: its type name, 0-based index among the messages read, the byte
    offset of its header, ``TimeUS`` (or ``TimeMS`` * 1000) when it has one, and its fields."""

    type: str
    index: int
    offset: int
    time_us: int | None
    fields: Mapping[str, Any]
    scales: Mapping[str, float] = field(default_factory=dict)
    clock_us: int | None = None  # pymavlink's clock: for records without TimeUS/TimeMS (pre-3.4 EV, 3.0 CURR)

    @property
    def when_s(self) -> float | None:
        """``TimeUS`` where the record has it, else pymavlink's clock at the record."""
        us = self.time_us if self.time_us is not None else self.clock_us
        return None if us is None else us / 1e6

    @property
    def time_s(self) -> float | None:
        return None if self.time_us is None else self.time_us / 1e6


@dataclass(frozen=True)
class BatteryRecord:
    """One battery monitor reading. ``instance`` is 0-based (ArduPilot prints it 1-based)."""

    time_s: float
    instance: int
    voltage_v: float | None
    current_a: float | None
    consumed_mah: float | None
    remaining_pct: float | None
    offset: int


@dataclass(frozen=True)
class ArmingRecord:
    time_s: float
    armed: bool
    offset: int


@dataclass
class DataflashLog:
    """An open log; :meth:`messages` may be walked more than once."""

    path: Path
    display: str
    text: bool = False
    skipped_notes: list[str] = field(default_factory=list)

    def messages(self, types: Iterable[str] | None = None) -> Iterator[DataflashMessage]:
        """The messages (of ``types`` when given), in file order."""
        wanted = None if types is None else set(types)
        reader = _open(self.path, self.display, self.skipped_notes, self.text)
        index = 0
        scales: dict[str, dict[str, float]] = {}
        try:
            while True:
                with _captured(self.skipped_notes):
                    try:
                        msg = reader.recv_match(type=sorted(wanted)) if wanted else reader.recv_msg()
                    except Exception as exc:  # pymavlink raises bare Exceptions on a corrupt FMT
                        raise InputError(self.display, 0, f"expected a DataFlash log: {exc}") from None
                if msg is None:
                    return
                name = msg.get_type()
                if name == "BAD_DATA":
                    continue
                length = int(getattr(getattr(msg, "fmt", None), "len", 0) or 0)
                try:  # a damaged FMT record can leave a message its columns do not describe
                    values = msg.to_dict()
                except Exception as exc:
                    self.skipped_notes.append(
                        f"{name} at offset {int(reader.offset) - length}: cannot decode ({exc!r})"
                    )
                    continue
                values.pop("mavpackettype", None)
                if name not in scales:
                    scales[name] = _scales(name, getattr(msg, "fmt", None))
                offset = max(0, int(reader.offset) - length)
                stamp = getattr(msg, "_timestamp", None)
                clock = None
                if isinstance(stamp, float | int) and math.isfinite(stamp):
                    clock = _bounded_us(round(stamp * 1e6))
                yield DataflashMessage(name, index, offset, _time_us(values), values, scales[name], clock)
                index += 1
        finally:
            with contextlib.suppress(Exception):
                reader.close()


def _scales(name: str, fmt: Any) -> dict[str, float]:
    if fmt is None:
        return {}
    units = getattr(fmt, "units", None)
    return field_scales(name, str(fmt.format), list(fmt.columns), bool(units))


def is_dataflash(path: Path) -> bool:
    """True when the file starts like a DataFlash log (a FMT message)."""
    try:
        with path.open("rb") as f:
            return f.read(3) == HEAD + bytes([FMT_TYPE])
    except OSError:
        return False


def open_log(path: Path, display: str | None = None) -> DataflashLog:
    """A DataFlash log, checked to start like one; InputError when it cannot be read."""
    shown = display or path.as_posix()
    try:
        with path.open("rb") as f:
            head = f.read(HEAD_BYTES)
    except OSError as exc:
        raise InputError(shown, 0, cannot_read(exc)) from None
    if not head:
        raise InputError(shown, 0, "expected a DataFlash log, got an empty file")
    if head[:3] == HEAD + bytes([FMT_TYPE]):
        return DataflashLog(path, shown)
    if is_text_dataflash(head):
        return DataflashLog(path, shown, text=True)
    raise InputError(
        shown, 0, "expected a DataFlash log (starting with a FMT message, bytes A3 95 80, or FMT, lines of text)"
    )


def _binary_reader(path: Path) -> Any:
    """pymavlink's binary reader, refusing a record that does not move it on (:func:`_guarded_reader`)."""
    return _guarded_reader()(str(path), zero_time_base=True)


@functools.cache
def _guarded_reader() -> Any:
    """pymavlink's binary reader class, made once, refusing a record that does not move it on. A format record may
    declare a length of 0: pymavlink then steps back over the header it just read and parses the same record again,
    for ever (found by the long fuzz run; tests/fuzz/crashers/view-dataflash/format-of-length-0.bin). Every other
    length moves it."""
    from pymavlink import DFReader

    class Guarded(DFReader.DFReader_binary):  # type: ignore[misc]
        def _parse_next(self) -> Any:
            before = self.offset
            msg = super()._parse_next()
            if msg is not None and self.offset <= before:
                raise ValueError(
                    f"a record at offset {before} of a format with no length (the reader would not move on)"
                )
            return msg

    return Guarded


def _open(path: Path, display: str, notes: list[str], text: bool = False) -> Any:
    # building the reader runs pymavlink's C indexer, which writes to the process's own descriptors: captured here,
    # once per open, not around every message read (a temporary file and four dups per message)
    with _captured(notes, native=True):
        try:
            if text:
                return open_text_reader(path)
            return _binary_reader(path)
        except (OSError, ValueError) as exc:
            raise InputError(display, 0, f"cannot read DataFlash log: {exc}") from None
        except Exception as exc:  # a corrupt FMT record: pymavlink raises a bare Exception
            raise InputError(display, 0, f"expected a DataFlash log: {exc}") from None


@contextlib.contextmanager
def _captured(notes: list[str], *, native: bool = False) -> Iterator[None]:
    """pymavlink's prints (skipped bytes, unknown formats) as notes instead of output: Python's prints, and with
    ``native`` what its C indexer writes to the process's own stderr/stdout (``Invalid length in FMT message at 0``),
    which no Python redirection sees; that text would reach a terminal or CI log unescaped, between battgen's lines."""
    out, err = io.StringIO(), io.StringIO()
    with (
        _fd_captured() if native else contextlib.nullcontext(lambda: "") as written,
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        yield
    for text in (out.getvalue(), err.getvalue(), written()):
        notes.extend(line for line in text.splitlines() if line.strip())


@contextlib.contextmanager
def _fd_captured() -> Iterator[Callable[[], str]]:
    """File descriptors 1 and 2 pointed at one temporary file while the block runs; yields what was written (read
    after the block, at most 64 KiB of it). Where the descriptors cannot be duplicated, nothing is captured."""
    captured = ""
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:
        yield lambda: captured
        return
    with tempfile.TemporaryFile() as sink:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield lambda: captured
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            captured = sink.read(65536).decode("utf-8", "replace")


# beyond this a record's time is damage, not a time (2^62 us: 146,000 years since boot), and the clock columns,
# microseconds in int64 plus a UTC offset, could not hold it
MAX_TIME_US = 1 << 62


def _time_us(values: Mapping[str, Any]) -> int | None:
    for name, scale in (("TimeUS", 1), ("TimeMS", 1000)):
        value = values.get(name)
        if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
            return _bounded_us(int(value) * scale)
    return None


def _bounded_us(us: int) -> int | None:
    """A time in microseconds, or None where it is no time (negative, or beyond MAX_TIME_US)."""
    return us if 0 <= us < MAX_TIME_US else None


def shortest_float32(value: float) -> float:
    """The shortest decimal that is the same float32 (``10.600000381469727`` -> ``10.6``): DataFlash
    floats are float32, and ArduPilot compares them as float32, so a logged 10.6 V must equal a
    10.6 V parameter here too."""
    if not math.isfinite(value) or value == 0:
        return value
    try:
        bits = struct.pack("<f", value)
    except OverflowError:
        return value
    for digits in range(6, 10):
        candidate = float(f"{value:.{digits}g}")
        if struct.pack("<f", candidate) == bits:
            return candidate
    return value


def _number(values: Mapping[str, Any], *names: str) -> float | None:
    for name in names:
        value = values.get(name)
        if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
            return shortest_float32(float(value)) if isinstance(value, float) else float(value)
    return None


def log_parameters(log: DataflashLog) -> dict[str, float]:
    """The PARM records as {name: value}; a name logged again takes its later value."""
    out: dict[str, float] = {}
    for msg in log.messages({"PARM"}):
        parameter = _parameter(msg)
        if parameter is not None:
            out[parameter[0]] = parameter[1]
    return out


def _parameter(msg: DataflashMessage) -> tuple[str, float] | None:
    """A PARM record's name and value (None: a record without them)."""
    name, value = msg.fields.get("Name"), _number(msg.fields, "Value")
    if isinstance(name, bytes):
        name = name.decode("ascii", "replace")
    if isinstance(name, str) and name and value is not None:
        return name.rstrip("\x00"), value
    return None


def _battery(msg: DataflashMessage) -> BatteryRecord | None:
    when = msg.when_s
    if when is None:
        return None
    f = msg.fields
    if msg.type in NUMBERED_TYPES:
        instance = NUMBERED_TYPES[msg.type]
    else:
        raw = f.get("Inst", f.get("Instance"))
        inst = raw if isinstance(raw, int) and not isinstance(raw, bool) else _number(f, "Inst", "Instance")
        instance = int(inst) if inst is not None else 0  # an integer as logged: a float would round 2^64 - 1
    return BatteryRecord(
        time_s=when,
        instance=instance,
        voltage_v=_scaled(msg, "Volt"),
        current_a=_scaled(msg, "Curr"),
        consumed_mah=_scaled(msg, "CurrTot"),
        remaining_pct=_scaled(msg, "RemPct"),
        offset=msg.offset,
    )


def _scaled(msg: DataflashMessage, name: str) -> float | None:
    value = _number(msg.fields, name)
    scale = msg.scales.get(name, 1.0)
    return value if value is None or scale == 1.0 else shortest_float32(value * scale)


def _arming(msg: DataflashMessage) -> ArmingRecord | None:
    when = msg.when_s
    if when is None:
        return None
    if msg.type == "ARM":
        state = _number(msg.fields, "ArmState")
        return None if state is None else ArmingRecord(when, bool(state), msg.offset)
    armed = event_state(_number(msg.fields, "Id"))
    return None if armed is None else ArmingRecord(when, armed, msg.offset)


def flight_records(log: DataflashLog) -> Iterator[BatteryRecord | ArmingRecord]:
    """Battery readings (every instance) and arming changes, in file order (one pass)."""
    for msg in log.messages(BATTERY_TYPES | ARMING_TYPES):
        item = _arming(msg) if msg.type in ARMING_TYPES else _battery(msg)
        if item is not None:
            yield item


@dataclass(frozen=True)
class LogStart:
    """The log's first record time (µs since boot), its ``LOG_DISARMED`` parameter as the log starts (None: not
    logged), the firmware string of its first ``MSG`` (``APM:Copter V3.3-dev (ae3192b8)``) and every ``PARM``
    record's value (:func:`log_parameters`' rule: a name logged again takes its later value)."""

    time_us: int | None
    log_disarmed: float | None
    firmware: str | None
    parameters: Mapping[str, float] = field(default_factory=dict)
    hardware: str | None = None  # the board, from the MSG that gives its name and unique id (BOARD_ID)
    texts: tuple[tuple[float | None, str], ...] = ()  # every MSG: (seconds on the log's clock, text)
    modes: tuple[tuple[float | None, int, int | None], ...] = ()  # every MODE: (seconds, mode number, reason)
    errors: tuple[tuple[float | None, int, int], ...] = ()  # every ERR: (seconds, subsystem, error code)
    events: tuple[tuple[float | None, int], ...] = ()  # every EV: (seconds, event id)


# ArduPilot's ModeReason (libraries/AP_Vehicle/ModeReason.h), the reasons a MODE record gives, up to the general
# FAILSAFE; a later number is shown as it is
MODE_REASONS = (
    "UNKNOWN",
    "RC_COMMAND",
    "GCS_COMMAND",
    "RADIO_FAILSAFE",
    "BATTERY_FAILSAFE",
    "GCS_FAILSAFE",
    "EKF_FAILSAFE",
    "GPS_GLITCH",
    "MISSION_END",
    "THROTTLE_LAND_ESCAPE",
    "FENCE_BREACHED",
    "TERRAIN_FAILSAFE",
    "BRAKE_TIMEOUT",
    "FLIP_COMPLETE",
    "AVOIDANCE",
    "AVOIDANCE_RECOVERY",
    "THROW_COMPLETE",
    "TERMINATE",
    "TOY_MODE",
    "CRASH_FAILSAFE",
    "SOARING_FBW_B_WITH_MOTOR_RUNNING",
    "SOARING_THERMAL_DETECTED",
    "SOARING_THERMAL_ESTIMATE_DETERIORATED",
    "VTOL_FAILED_TRANSITION",
    "VTOL_FAILED_TAKEOFF",
    "FAILSAFE",
)
# ArduPilot's failsafe subsystems of an ERR record (AP_Logger's LogErrorSubsystem); ECode 0 is "resolved"
FAILSAFE_SUBSYSTEMS = {
    5: "FAILSAFE_RADIO",
    6: "FAILSAFE_BATT",
    7: "FAILSAFE_GPS",
    8: "FAILSAFE_GCS",
    9: "FAILSAFE_FENCE",
}
# ArduPilot's LogEvent ids (AP_Logger.h), the events an EV record gives; with the ids older firmware logged as EV
# (DATA_SYSTEM_TIME_SET 8, DATA_TAKEOFF 16, DATA_EXIT_FLIP 23, DATA_SAVEWP_CLEAR_MISSION_RTL 40), which are no
# longer events. An id not here is shown as ``EV <id>``.
LOG_EVENTS = {
    7: "AP_STATE",
    8: "SYSTEM_TIME_SET",
    9: "INIT_SIMPLE_BEARING",
    10: "ARMED",
    11: "DISARMED",
    15: "AUTO_ARMED",
    16: "TAKEOFF",
    17: "LAND_COMPLETE_MAYBE",
    18: "LAND_COMPLETE",
    19: "LOST_GPS",
    21: "FLIP_START",
    22: "FLIP_END",
    23: "EXIT_FLIP",
    25: "SET_HOME",
    26: "SET_SIMPLE_ON",
    27: "SET_SIMPLE_OFF",
    28: "NOT_LANDED",
    29: "SET_SUPERSIMPLE_ON",
    30: "AUTOTUNE_INITIALISED",
    31: "AUTOTUNE_OFF",
    32: "AUTOTUNE_RESTART",
    33: "AUTOTUNE_SUCCESS",
    34: "AUTOTUNE_FAILED",
    35: "AUTOTUNE_REACHED_LIMIT",
    36: "AUTOTUNE_PILOT_TESTING",
    37: "AUTOTUNE_SAVEDGAINS",
    38: "SAVE_TRIM",
    39: "SAVEWP_ADD_WP",
    40: "SAVEWP_CLEAR_MISSION_RTL",
    41: "FENCE_ENABLE",
    42: "FENCE_DISABLE",
    43: "ACRO_TRAINER_OFF",
    44: "ACRO_TRAINER_LEVELING",
    45: "ACRO_TRAINER_LIMITED",
    46: "GRIPPER_GRAB",
    47: "GRIPPER_RELEASE",
    49: "PARACHUTE_DISABLED",
    50: "PARACHUTE_ENABLED",
    51: "PARACHUTE_RELEASED",
    52: "LANDING_GEAR_DEPLOYED",
    53: "LANDING_GEAR_RETRACTED",
    54: "MOTORS_EMERGENCY_STOPPED",
    55: "MOTORS_EMERGENCY_STOP_CLEARED",
    56: "MOTORS_INTERLOCK_DISABLED",
    57: "MOTORS_INTERLOCK_ENABLED",
    58: "ROTOR_RUNUP_COMPLETE",
    59: "ROTOR_SPEED_BELOW_CRITICAL",
    60: "EKF_ALT_RESET",
    61: "LAND_CANCELLED_BY_PILOT",
    62: "EKF_YAW_RESET",
    63: "AVOIDANCE_ADSB_ENABLE",
    64: "AVOIDANCE_ADSB_DISABLE",
    65: "AVOIDANCE_PROXIMITY_ENABLE",
    66: "AVOIDANCE_PROXIMITY_DISABLE",
    67: "GPS_PRIMARY_CHANGED",
    71: "ZIGZAG_STORE_A",
    72: "ZIGZAG_STORE_B",
    73: "LAND_REPO_ACTIVE",
    74: "STANDBY_ENABLE",
    75: "STANDBY_DISABLE",
    76: "FENCE_ALT_MAX_ENABLE",
    77: "FENCE_ALT_MAX_DISABLE",
    78: "FENCE_CIRCLE_ENABLE",
    79: "FENCE_CIRCLE_DISABLE",
    80: "FENCE_ALT_MIN_ENABLE",
    81: "FENCE_ALT_MIN_DISABLE",
    82: "FENCE_POLYGON_ENABLE",
    83: "FENCE_POLYGON_DISABLE",
    85: "EK3_SOURCES_SET_TO_PRIMARY",
    86: "EK3_SOURCES_SET_TO_SECONDARY",
    87: "EK3_SOURCES_SET_TO_TERTIARY",
    90: "AIRSPEED_PRIMARY_CHANGED",
    163: "SURFACED",
    164: "NOT_SURFACED",
    165: "BOTTOMED",
    166: "NOT_BOTTOMED",
}
# the vehicle a firmware string names, as MAV_TYPE, for pymavlink's table of its mode numbers
_FIRMWARE_MAV_TYPE = (("Copter", 2), ("Plane", 1), ("Rover", 10), ("Sub", 12), ("Tracker", 5))


def mode_name(number: int, firmware: str | None) -> str:
    """An ArduPilot mode number by name, for the vehicle its firmware string names (pymavlink's tables), else
    ``mode N``."""
    mav_type = next((t for word, t in _FIRMWARE_MAV_TYPE if firmware and word in firmware), None)
    if mav_type is not None:
        from pymavlink import mavutil  # the DataFlash reader's own dependency

        names = mavutil.mode_mapping_bynumber(mav_type) or {}
        if number in names:
            return str(names[number])
    return f"mode {number}"


def event_name(event: int) -> str:
    """An EV record's id by ArduPilot's name for it, else ``EV <id>``."""
    return LOG_EVENTS.get(event, f"EV {event}")


def reason_name(reason: int) -> str:
    return MODE_REASONS[reason] if 0 <= reason < len(MODE_REASONS) else f"reason {reason}"


def timed_flight_records(log: DataflashLog) -> Iterator[BatteryRecord | ArmingRecord | GpsClock | LogStart]:
    """As :func:`flight_records`, with every GPS record that tells the time (:class:`GpsClock`), in
    the same pass, and last a :class:`LogStart`."""
    start = first_time_us(log)  # a short pass: the unfiltered walk is ~15x slower than a filtered one
    log_disarmed: float | None = None
    firmware: str | None = None
    hardware: str | None = None
    parameters: dict[str, float] = {}
    texts: list[tuple[float | None, str]] = []
    modes: list[tuple[float | None, int, int | None]] = []
    errors: list[tuple[float | None, int, int]] = []
    events: list[tuple[float | None, int]] = []
    for msg in log.messages(BATTERY_TYPES | ARMING_TYPES | {"GPS", "PARM", "MSG", "MODE", "ERR"}):
        if msg.type == "GPS":
            clock = _gps_clock(msg)
            if clock is not None:
                yield clock
        elif msg.type in ARMING_TYPES:
            arm = _arming(msg)
            if arm is not None:
                yield arm
            event = _number(msg.fields, "Id") if msg.type == "EV" else None
            if event is not None:
                events.append((msg.when_s, int(event)))
        elif msg.type in BATTERY_TYPES:
            bat = _battery(msg)
            if bat is not None:
                yield bat
        elif msg.type == "PARM":
            parameter = _parameter(msg)
            if parameter is not None:
                parameters[parameter[0]] = parameter[1]
                if parameter[0] == "LOG_DISARMED" and log_disarmed is None:
                    log_disarmed = parameter[1]
        elif msg.type == "MODE":
            number, reason = _number(msg.fields, "ModeNum"), _number(msg.fields, "Rsn")
            number = number if number is not None else _number(msg.fields, "Mode")
            if number is not None:
                modes.append((msg.when_s, int(number), None if reason is None else int(reason)))
        elif msg.type == "ERR":
            subsystem, code = _number(msg.fields, "Subsys"), _number(msg.fields, "ECode")
            if subsystem is not None and code is not None:
                errors.append((msg.when_s, int(subsystem), int(code)))
        elif msg.type == "MSG":
            text = msg.fields.get("Message")
            if isinstance(text, bytes):
                text = text.decode("ascii", "replace")
            if not isinstance(text, str):
                continue
            text = text.rstrip("\x00")
            texts.append((msg.when_s, text))
            if firmware is not None and hardware is not None:
                continue
            board = BOARD_ID.fullmatch(text)
            if board is not None and hardware is None:
                hardware = board.group(1)
            elif firmware is None and (" V" in text or text.startswith(("Ardu", "APM"))):
                firmware = text
    yield LogStart(
        start, log_disarmed, firmware, parameters, hardware, tuple(texts), tuple(modes), tuple(errors), tuple(events)
    )


GPS_EPOCH_S = 315_964_800  # 1980-01-06 00:00 UTC, the start of GPS week 0, in Unix time
GPS_LEAP_S = 18  # GPS time runs ahead of UTC by the leap seconds since 1980 (18 since 2017, as pymavlink counts)


@dataclass(frozen=True)
class GpsClock:
    """A GPS record's time (``GWk`` week, ``GMS`` ms of the week) against the log's ``TimeUS``:
    ``utc_us - time_us`` turns the log's clock into µs since the Unix epoch (UTC)."""

    time_us: int
    utc_us: int


def _gps_clock(msg: DataflashMessage) -> GpsClock | None:
    """The clock of a GPS record that has a week (pymavlink's DFReader takes the first with ``GWk`` > 0)."""
    week, ms = _number(msg.fields, "GWk"), _number(msg.fields, "GMS")
    # a week of uint16 and a time within the week, as ArduPilot logs them (GWk H, GMS I): anything else is damage,
    # and would push the UTC clock beyond the int64 microseconds the clock columns hold
    if msg.time_us is None or week is None or ms is None or not 0 < week <= 0xFFFF or not 0 <= ms < 604_800_000:
        return None
    return GpsClock(msg.time_us, (GPS_EPOCH_S + int(week) * 604_800 - GPS_LEAP_S) * 1_000_000 + int(ms) * 1000)


def first_time_us(log: DataflashLog) -> int | None:
    """The log's start: the ``TimeUS`` (or ``TimeMS``) of its first record that has one."""
    for msg in log.messages():
        if msg.time_us is not None:
            return msg.time_us
        if msg.type in BATTERY_TYPES and msg.clock_us is not None:  # a log without TimeUS/TimeMS at all
            return msg.clock_us
    return None


def battery_records(log: DataflashLog) -> Iterator[BatteryRecord]:
    """Every battery reading of the log (all instances), in file order."""
    for msg in log.messages(BATTERY_TYPES):
        item = _battery(msg)
        if item is not None:
            yield item


def arming_records(log: DataflashLog) -> Iterator[ArmingRecord]:
    """Arming state changes: ARM.ArmState, else EV ids 10 (armed) / 11 (disarmed)."""
    for msg in log.messages(ARMING_TYPES):
        item = _arming(msg)
        if item is not None:
            yield item
