"""What a log says about itself, stated once per log by the source that reads it (:mod:`.readers`).

Every command that reads a log through the battery view gets the same :class:`LogContext` with its chunks
(``Batch.context``): the clock, the vehicle and its firmware, the arming state over the whole log and the
parameters the firmware recorded. Per kind:

- **PX4 ULog**: the clock is the log's own (µs since boot, ``t`` = 0 at the header's timestamp), UTC from the
  first GPS record with ``time_utc_usec``; vehicle ``sys_uuid``; firmware ``sys_name`` with the release
  ``ver_sw_release`` decodes to (``0xAABBCCTT``: major, minor, patch, type) and the commit ``ver_sw``; hardware
  ``ver_hw``; vehicle type PX4's ``MAV_TYPE`` parameter; parameters the log's initial values (``PARAM``
  definitions; a value changed in flight is not applied: the replay starts from what the vehicle took off with).
- **ArduPilot DataFlash**: the clock ``TimeUS`` since boot (``t`` = 0 at the first record), UTC from the first
  GPS record with a week; firmware the first ``MSG`` that names it (``APM:Copter V3.3-dev (ae3192b8)``), hardware
  the board the start-up ``MSG`` names with its unique id (``Pixhawk4 0047002B 34385105 36363539``); the
  parameters every ``PARM`` record (a value set again in flight: its last, as the vehicle ended up with it), under
  the names the firmware logged (older names such as ``FS_BATT_VOLTAGE`` are the failsafe's to map).
- **MAVLink tlog**: the clock the tlog's stamps (µs since the epoch, so UTC is known); the vehicle the system id
  of the vehicle heartbeats; vehicle type their ``type`` (MAV_TYPE) and the firmware family their ``autopilot``
  (MAV_AUTOPILOT); the parameters its PARAM_VALUE frames (a ground station's parameter download; a value sent
  again: its last), ArduPilot's as numbers, PX4's integers decoded from the float's bytes.
- **CAN captures, JSON Lines**: the clock only; no arming state, no firmware, no parameters.

``arming`` is the log's arming state as changes of state in ``t``, by the kind's one rule (``arming_rule``);
``armed_intervals`` gives them as [start, end) spans. What the firmware said and did, where the log keeps it:
``texts`` its logged messages (ULog ``L``/``C`` records with their syslog level, DataFlash ``MSG``), ``modes`` its
flight-mode changes (PX4 ``vehicle_status.nav_state``; DataFlash ``MODE`` with the reason ArduPilot gave), and
``failsafes`` the moments it entered a failsafe (PX4 ``vehicle_status.failsafe`` turning true, with the mode it
chose, and each rise of the battery inputs of commander's failsafe framework, ``failsafe_flags.battery_warning``
and ``battery_low_remaining_time``; ArduPilot a ``MODE`` change for a failsafe reason and ``ERR`` records of a
failsafe subsystem), and ``events`` the events it logged as such (DataFlash ``EV`` records, by AP_Logger's names:
``ARMED``, ``LAND_COMPLETE``, ``MOTORS_EMERGENCY_STOPPED``...).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .columns import NDArray

MAV_AUTOPILOT_FIRMWARE = {3: "ardupilot", 12: "px4"}  # MAV_AUTOPILOT_ARDUPILOTMEGA, MAV_AUTOPILOT_PX4
PX4_RELEASE_TYPES = ((255, ""), (192, "rc"), (128, "beta"), (64, "alpha"), (0, "dev"))  # the type byte's lower bound

PARAMETER_SOURCES = {"ulog": "PARAM definitions", "dataflash": "PARM records", "tlog": "PARAM_VALUE frames"}
ARMING_RULES = {
    "ulog": "vehicle_status.arming_state == ARMED (actuator_armed.armed where the log lacks vehicle_status)",
    "dataflash": "ARM.ArmState, else EV 10/11 (and 15 AUTO_ARMED); armed from the first record when LOG_DISARMED=0 "
    "and no ARM record precedes it",
    "tlog": "HEARTBEAT.base_mode & MAV_MODE_FLAG_SAFETY_ARMED of the vehicle's latest heartbeat",
}


@dataclass(frozen=True)
class LogText:
    """A message the firmware logged: at ``t``, its severity (a syslog name: ``warning``, ``info``...; "" where
    the log gives none) and its text."""

    t: float
    severity: str
    text: str


SYSLOG_LEVELS = ("emergency", "alert", "critical", "error", "warning", "notice", "info", "debug")


@dataclass(frozen=True)
class LogContext:
    """A log's context (see the module's docs); ``None`` fields are what the log does not say."""

    kind: str
    start_us: int | None = None  # the log's own clock at t = 0 (ULog, DataFlash: µs since boot; tlog: since epoch)
    utc_offset_us: int | None = None  # the log's clock + this = µs since the Unix epoch
    vehicle: str | None = None  # the vehicle's id in the log (ULog sys_uuid, tlog "mavlink:<sysid>")
    vehicle_type: int | None = None  # MAV_TYPE
    autopilot: str | None = None  # the firmware family: "px4" or "ardupilot"
    firmware: str | None = None  # as the log names it, version included
    hardware: str | None = None
    parameters: Mapping[str, float] = field(default_factory=dict)
    arming: tuple[tuple[float, bool], ...] = ()  # (t, armed) at each change of the arming state
    arming_rule: str = ""  # "" where the log carries no arming state
    texts: tuple[LogText, ...] = ()
    modes: tuple[tuple[float, str], ...] = ()  # (t, the mode entered, with the reason where the log gives one)
    failsafes: tuple[tuple[float, str], ...] = ()  # (t, what the firmware did or which failsafe)
    events: tuple[tuple[float, str], ...] = ()  # (t, the event the firmware logged, by its name)

    @property
    def start_utc_us(self) -> int | None:
        """µs since the epoch at t = 0, where the log tells UTC."""
        if self.start_us is None or self.utc_offset_us is None:
            return None
        return self.start_us + self.utc_offset_us

    def armed_intervals(self, end: float) -> list[tuple[float, float]]:
        """The [start, end) spans of ``t`` the vehicle was armed, the last closed at ``end``."""
        out: list[tuple[float, float]] = []
        since: float | None = None
        for t, armed in self.arming:
            if armed and since is None:
                since = t
            elif not armed and since is not None:
                out.append((since, t))
                since = None
        if since is not None and end > since:
            out.append((since, end))
        return out

    @property
    def parameters_from(self) -> str:
        """Where the log keeps its parameters, as a person names it ("PARM records")."""
        return PARAMETER_SOURCES.get(self.kind, "parameters")

    def to_dict(self, end: float | None = None) -> dict[str, object]:
        """The context as JSON data; the parameters as a count (a log holds hundreds), the modes, failsafes, events
        and logged texts in full."""
        out: dict[str, object] = {
            "kind": self.kind,
            "start_utc_us": self.start_utc_us,
            "vehicle": self.vehicle,
            "vehicle_type": self.vehicle_type,
            "autopilot": self.autopilot,
            "firmware": self.firmware,
            "hardware": self.hardware,
            "parameters": len(self.parameters),
            "arming_rule": self.arming_rule or None,
        }
        if end is not None:
            out["armed"] = [list(span) for span in self.armed_intervals(end)] if self.arming_rule else None
        # what the firmware said and did, as the report's page shows it (each at t, seconds since the log's start)
        out["modes"] = [{"t": t, "mode": name} for t, name in self.modes]
        out["failsafes"] = [{"t": t, "failsafe": what} for t, what in self.failsafes]
        out["events"] = [{"t": t, "event": what} for t, what in self.events]
        out["texts"] = [{"t": x.t, "severity": x.severity or None, "text": x.text} for x in self.texts]
        return out


def arming_changes(t: NDArray, armed: NDArray) -> tuple[tuple[float, bool], ...]:
    """The changes of an arming state given at times ``t`` (in ``t`` order; unknown states left out): the first
    known state, then each change. A state known from before the log's start (``-inf``) counts from t = 0."""
    order = np.argsort(t, kind="stable")
    out: list[tuple[float, bool]] = []
    for tk, ak in zip(
        np.asarray(t, np.float64)[order].tolist(), np.asarray(armed, np.float64)[order].tolist(), strict=True
    ):
        if ak != ak or tk != tk:
            continue
        state = bool(ak)
        if not out or out[-1][1] != state:
            out.append((max(tk, 0.0), state))
    return tuple(out)


def px4_firmware(info: Mapping[str, object]) -> str | None:
    """A ULog's firmware as a person names it: ``PX4 v1.15.0-dev (cb09dde6)`` from ``sys_name``, ``ver_sw_release``
    and ``ver_sw``."""
    name = info.get("sys_name")
    release = info.get("ver_sw_release")
    commit = info.get("ver_sw")
    parts = [str(name) if name else "PX4"]
    if isinstance(release, int) and not isinstance(release, bool) and release > 0:
        major, minor, patch, kind = (
            (release >> 24) & 0xFF,
            (release >> 16) & 0xFF,
            (release >> 8) & 0xFF,
            release & 0xFF,
        )
        suffix = next(label for bound, label in PX4_RELEASE_TYPES if kind >= bound)
        parts.append(f"v{major}.{minor}.{patch}" + (f"-{suffix}" if suffix else ""))
    if isinstance(commit, str) and commit:
        parts.append(f"({commit[:8]})")
    return " ".join(parts) if len(parts) > 1 or name else None


# PX4's vehicle_status.nav_state values whose names every release since 1.14 keeps (msg/VehicleStatus.msg); the
# others were renamed or reused between releases and are shown by number
PX4_NAV_STATES = {
    0: "MANUAL",
    1: "ALTCTL",
    2: "POSCTL",
    3: "AUTO_MISSION",
    4: "AUTO_LOITER",
    5: "AUTO_RTL",
    10: "ACRO",
    12: "DESCEND",
    13: "TERMINATION",
    14: "OFFBOARD",
    15: "STAB",
    17: "AUTO_TAKEOFF",
    18: "AUTO_LAND",
    19: "AUTO_FOLLOW_TARGET",
    20: "AUTO_PRECLAND",
    21: "ORBIT",
    22: "AUTO_VTOL_TAKEOFF",
}


def px4_modes(
    states: tuple[NDArray, NDArray, NDArray | None] | None, start_us: int
) -> tuple[tuple[tuple[float, str], ...], tuple[tuple[float, str], ...]]:
    """PX4's mode changes (each change of ``nav_state``, the first state too) and failsafe entries (``failsafe``
    turning true, with the mode commander chose), in ``t``, from ``vehicle_status`` records."""
    if states is None:
        return (), ()
    stamps, navs, failsafe = states
    t = (np.asarray(stamps, np.int64) - start_us) / 1e6
    modes: list[tuple[float, str]] = []
    failsafes: list[tuple[float, str]] = []
    last_nav: int | None = None
    was_failsafe = False
    flags = [False] * len(t) if failsafe is None else np.asarray(failsafe, bool).tolist()
    for tk, nav, fs in zip(t.tolist(), np.asarray(navs).tolist(), flags, strict=True):
        name = PX4_NAV_STATES.get(int(nav), f"nav_state {int(nav)}")
        if nav != last_nav:
            modes.append((max(tk, 0.0), name))
            last_nav = nav
        if fs and not was_failsafe:
            failsafes.append((max(tk, 0.0), f"failsafe: {name}"))
        was_failsafe = bool(fs)
    return tuple(modes), tuple(failsafes)


PX4_WARNINGS = {1: "LOW", 2: "CRITICAL", 3: "EMERGENCY"}  # battery_status.warning / failsafe_flags.battery_warning


def px4_battery_failsafes(
    flags: tuple[NDArray, NDArray, NDArray | None] | None, start_us: int
) -> tuple[tuple[float, str], ...]:
    """Each rise of commander's battery warning and each time its remaining-flight-time flag turns true, in ``t``,
    from ``failsafe_flags`` records."""
    if flags is None:
        return ()
    stamps, warnings, low_time = flags
    t = ((np.asarray(stamps, np.int64) - start_us) / 1e6).tolist()
    lows = [False] * len(t) if low_time is None else np.asarray(low_time, bool).tolist()
    out: list[tuple[float, str]] = []
    level, was_low = 0, False
    for tk, w, low in zip(t, np.asarray(warnings).tolist(), lows, strict=True):
        if w > level and w in PX4_WARNINGS:
            out.append((max(tk, 0.0), f"battery warning {PX4_WARNINGS[w]} (failsafe_flags)"))
        level = int(w)
        if low and not was_low:
            out.append((max(tk, 0.0), "remaining flight time low (failsafe_flags)"))
        was_low = bool(low)
    return tuple(out)
