"""What the log says about itself, as the report shows it first: the header, the battery parameters, the armed
spans, the firmware's own warning levels and the thresholds the page draws.

Everything here is read off the log's :class:`~codegen.apps.battery.context.LogContext` (the data layer's one
reading of vehicle, firmware, clock, parameters and arming) and the battery series' ``warning`` concept (PX4's
``battery_status.warning``, MAVLink's ``charge_state``, DroneCAN's status flags: what the firmware itself decided).
The thresholds: PX4's are fractions of the state of charge (``BAT_LOW_THR``, ``BAT_CRIT_THR``,
``BAT_EMERGEN_THR``, as ``battery.cpp`` compares them with the estimated remaining charge), drawn on the state of
charge; ArduPilot's are the failsafe replay's volts (:mod:`.replay`). ``--params`` overrides the log's values.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime

import numpy as np

from ..battery.columns import NDArray
from ..battery.context import LogContext, LogText
from ..schemas.package import bundled_package, package_module

# the parameters about the battery a person looks for: PX4's BAT*_ and COM_*BAT*, ArduPilot's BATT*_ and older FS_BATT_*
BATTERY_PARAMETER = re.compile(r"^(BAT\d*_|BATT\d?_|COM_[A-Z_]*BAT|FS_BATT_)")
# a logged message that concerns the battery (or a failsafe the battery may have caused), by its words
BATTERY_TEXT = re.compile(r"batt|volt|cell|charg|capacity|power|current|energy|failsafe", re.IGNORECASE)
# PX4's state-of-charge thresholds (battery.cpp: remaining < BAT_*_THR sets the warning), fractions
PX4_SOC_THRESHOLDS = ("BAT_LOW_THR", "BAT_CRIT_THR", "BAT_EMERGEN_THR")


@dataclass(frozen=True)
class WarningChange:
    """The firmware's own warning level of one battery changing at ``t`` to ``level`` (a warning concept choice)."""

    t: float
    battery: int
    level: str


@dataclass
class LogFacts:
    """The header rows, the battery parameters and where the thresholds come from, of one input."""

    header: list[tuple[str, str]] = field(default_factory=list)
    parameters: list[tuple[str, str]] = field(default_factory=list)
    parameters_from: str = ""
    armed: list[tuple[float, float]] = field(default_factory=list)
    soc_thresholds: dict[str, float] = field(default_factory=dict)  # name -> percent
    thresholds_from: str = ""
    autopilot: str | None = None
    texts: list[LogText] = field(default_factory=list)  # every message the firmware logged
    battery_texts: list[LogText] = field(default_factory=list)  # those about the battery or a failsafe
    modes: list[tuple[float, str]] = field(default_factory=list)  # (t, mode entered)
    failsafes: list[tuple[float, str]] = field(default_factory=list)  # (t, what the firmware's failsafe did)
    events: list[tuple[float, str]] = field(default_factory=list)  # (t, an event the firmware logged)


def vehicle_type_name(code: int | None) -> str | None:
    """MAV_TYPE as a person reads it (``quadrotor (MAV_TYPE 2)``), from the generated MAVLink enum."""
    if code is None:
        return None
    try:
        name = package_module(bundled_package(), "mavlink").MavType(code).name
    except (ValueError, AttributeError):
        return f"MAV_TYPE {code}"
    return f"{str(name).lower().replace('_', ' ')} (MAV_TYPE {code})"


def utc_text(us: int | None) -> str | None:
    if us is None:
        return None
    return datetime.fromtimestamp(us / 1e6, UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def number_text(value: float) -> str:
    """A parameter as the log holds it: integers without a fraction, floats at their shortest."""
    if math.isfinite(value) and value == int(value) and abs(value) < 1e15:
        return str(int(value))
    return repr(value)  # nan, inf, a fraction: as Python spells the shortest form


def duration_text(seconds: float) -> str:
    minutes, s = divmod(seconds, 60.0)
    return f"{seconds:.1f} s" if minutes < 1 else f"{int(minutes)} min {s:04.1f} s ({seconds:.1f} s)"


def log_facts(
    context: LogContext | None, end: float, override: Mapping[str, float] | None = None, override_from: str = ""
) -> LogFacts:
    """The facts of a log ending at ``end`` s (``context`` None: a data file, which says nothing of itself);
    ``override``: the values of ``--params``, which replace the log's for the thresholds."""
    facts = LogFacts()
    if context is None:
        facts.header = [
            ("log", "a data file: no vehicle, firmware or clock of its own"),
            ("duration", duration_text(end)),
        ]
    else:
        facts.autopilot = context.autopilot
        rows = [
            ("vehicle type", vehicle_type_name(context.vehicle_type)),
            ("firmware", context.firmware or context.autopilot),
            ("hardware", context.hardware),
            ("vehicle", context.vehicle),
            ("log start", utc_text(context.start_utc_us) or "unknown in UTC (the log has no GPS time)"),
            ("duration", duration_text(end)),
        ]
        facts.header = [(k, v) for k, v in rows if v]
        if context.arming_rule:
            facts.armed = context.armed_intervals(end)
            spans = ", ".join(f"{a:.1f}–{b:.1f} s" for a, b in facts.armed) or "never"
            facts.header.append(("armed", spans))
        facts.parameters = [
            (k, number_text(v)) for k, v in sorted(context.parameters.items()) if BATTERY_PARAMETER.match(k)
        ]
        facts.parameters_from = f"the log's {context.parameters_from}" if context.parameters else ""
        facts.texts = list(context.texts)
        facts.battery_texts = [m for m in context.texts if BATTERY_TEXT.search(m.text)]
        facts.modes = [(t, name) for t, name in context.modes if t <= end]
        facts.failsafes = [(t, what) for t, what in context.failsafes if t <= end]
        facts.events = [(t, what) for t, what in context.events if t <= end]
        if facts.modes:
            shown = ", ".join(f"{name} {t:.1f} s" for t, name in facts.modes[:8])
            facts.header.append(
                ("flight modes", shown + (f", … ({len(facts.modes)} changes)" if len(facts.modes) > 8 else ""))
            )
    values: Mapping[str, float] = context.parameters if context is not None else {}
    facts.thresholds_from = facts.parameters_from
    if override:
        values, facts.thresholds_from = override, override_from
    if facts.autopilot == "px4" or any(k in values for k in PX4_SOC_THRESHOLDS):
        facts.soc_thresholds = {k: float(values[k]) * 100.0 for k in PX4_SOC_THRESHOLDS if float(values.get(k, 0)) > 0}
    return facts


def warning_changes(t: NDArray, warning: NDArray, battery: int, levels: tuple[str, ...]) -> list[WarningChange]:
    """Each change of the firmware's own warning level (the first known level too, when it is not the first of
    ``levels``, the warning concept's choices: ``none``)."""
    out: list[WarningChange] = []
    last: float | None = None
    for tk, code in zip(t.tolist(), np.asarray(warning, np.float64).tolist(), strict=True):
        if code != code or code == last:
            continue
        if last is not None or code != 0:
            index = int(code)
            out.append(WarningChange(tk, battery, levels[index] if 0 <= index < len(levels) else str(index)))
        last = code
    return out
