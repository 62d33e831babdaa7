"""PX4's battery warning levels: what the battery library computes per battery, and what commander makes of them.

From PX4-Autopilot's source (each rule pinned in ``tests/apps/test_px4_failsafe.py``):

- ``src/lib/battery/battery.cpp`` ``Battery::determineWarning``: EMERGENCY below ``BAT_EMERGEN_THR``, else
  CRITICAL below ``BAT_CRIT_THR``, else LOW below ``BAT_LOW_THR``, else NONE, comparing the state of charge
  (``battery_status.remaining``) as float32 with strict ``<``;
- ``Battery::updateBatteryStatus``: the warning is only recomputed while the battery is connected and initialized
  (connected for more than 2 s); otherwise it keeps its last value. Since v1.12 it is recomputed every update, so
  it drops back when the estimate rises; older releases latched it ("propagate warning state only if the state is
  higher", the ``latched`` rule below), from PR #13470 (v1.11) only while armed;
- ``src/modules/commander/HealthAndArmingChecks/checks/batteryCheck.cpp`` ``BatteryChecks::checkAndReport``: the
  failsafe's warning (``failsafe_flags.battery_warning``) is the worst warning of the connected batteries; while
  armed it only rises ("if armed, only allow increase of battery warning severity"), while disarmed it follows.

Parameter defaults (``src/lib/battery/battery_params_common.c``, later ``module.yaml``; the same in the releases the
corpus's logs name): ``BAT_LOW_THR`` 0.15, ``BAT_CRIT_THR`` 0.07, ``BAT_EMERGEN_THR`` 0.05.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..battery.columns import NDArray

INITIALIZE_S = 2.0  # battery.cpp: _battery_initialized = connected and timestamp > _last_unconnected_timestamp + 2_s
LATCHED_BEFORE = (1, 12)  # releases before v1.12 latch the battery's warning (see the module's docs)
DEFAULTS: dict[str, float] = {"BAT_LOW_THR": 0.15, "BAT_CRIT_THR": 0.07, "BAT_EMERGEN_THR": 0.05}


class Px4Level(enum.IntEnum):
    """``battery_status.warning`` (msg/BatteryStatus.msg WARNING_*)."""

    NONE = 0
    LOW = 1
    CRITICAL = 2
    EMERGENCY = 3


@dataclass(frozen=True)
class Thresholds:
    """The three state-of-charge thresholds as the firmware holds them (float32)."""

    low: float = DEFAULTS["BAT_LOW_THR"]
    critical: float = DEFAULTS["BAT_CRIT_THR"]
    emergency: float = DEFAULTS["BAT_EMERGEN_THR"]

    @classmethod
    def from_values(cls, values: Mapping[str, float]) -> Thresholds:
        """From a parameter set (absent ones at PX4's defaults); a value that is no finite number is a ValueError."""

        def get(name: str) -> float:
            value = values.get(name, DEFAULTS[name])
            if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
                raise ValueError(f"{name}: expected a finite number, got {value!r}")
            return float(value)

        return cls(get("BAT_LOW_THR"), get("BAT_CRIT_THR"), get("BAT_EMERGEN_THR"))

    def threshold(self, level: Px4Level) -> float:
        return {Px4Level.LOW: self.low, Px4Level.CRITICAL: self.critical, Px4Level.EMERGENCY: self.emergency}.get(
            level, float("nan")
        )


def determine_warning(remaining: NDArray | float, thresholds: Thresholds) -> NDArray:
    """``Battery::determineWarning`` over a column of states of charge (float32 comparisons, as the firmware's)."""
    soc = np.asarray(remaining, np.float32)
    out = np.full(soc.shape, int(Px4Level.NONE), np.int8)
    out[soc < np.float32(thresholds.low)] = Px4Level.LOW
    out[soc < np.float32(thresholds.critical)] = Px4Level.CRITICAL
    out[soc < np.float32(thresholds.emergency)] = Px4Level.EMERGENCY
    return out


def release_of(firmware: str | None) -> tuple[int, int, int] | None:
    """The release a log's firmware names (``PX4 v1.14.0 (b8c541dd)`` -> (1, 14, 0)); None when it names none."""
    m = re.search(r"v(\d+)\.(\d+)\.(\d+)", firmware or "")
    return (int(m.group(1)), int(m.group(2)), int(m.group(3))) if m else None


def latches(release: tuple[int, int, int] | None) -> bool:
    """Whether the battery library of a release keeps its warning from falling (before v1.12); unknown: no."""
    return release is not None and release[:2] < LATCHED_BEFORE


def battery_warnings(
    boot_s: NDArray,
    remaining: NDArray,
    connected: NDArray,
    thresholds: Thresholds,
    *,
    latched: bool = False,
) -> NDArray:
    """One battery's ``battery_status.warning`` per update, as ``Battery::updateBatteryStatus`` computes it.

    ``boot_s``: each update's time since boot (the battery library's clock); ``connected``: the published flag. The
    warning keeps its value (NONE at the start) where the battery is not connected or not yet initialized (connected
    for more than 2 s, counted from its first update, which a log cannot show and is taken as at boot, or its last
    unconnected one). ``latched``: the releases that only let it rise."""
    levels = determine_warning(remaining, thresholds)
    n = len(levels)
    if not n:
        return np.zeros(0, np.int8)
    t = np.asarray(boot_s, np.float64)  # as the Python floats of a per-update loop: the sum below in float64
    ok = np.asarray(connected, bool)
    at = np.arange(n)
    # the last unconnected update so far (the first update, taken as at boot, where there is none)
    last_off = np.maximum.accumulate(np.where(ok, -1, at))
    since = np.where(last_off >= 0, t[np.maximum(last_off, 0)], 0.0)
    update = ok & (t > since + INITIALIZE_S)
    if latched:  # only rises: the highest level of the updates so far (NONE = 0 before any)
        return np.asarray(np.maximum.accumulate(np.where(update, levels, 0)), np.int8)
    last = np.maximum.accumulate(np.where(update, at, -1))  # the level of the last update, NONE before any
    return np.asarray(np.where(last >= 0, levels[np.maximum(last, 0)], 0), np.int8)


def commander_warning(per_battery: list[tuple[NDArray, NDArray, NDArray]], t: NDArray, armed: NDArray) -> NDArray:
    """``failsafe_flags.battery_warning`` at each of the times ``t`` (``BatteryChecks::checkAndReport``): the worst
    latest warning of the connected batteries, only rising while ``armed``. ``per_battery``: each battery's (times,
    warnings, connected) in time order."""
    worst = np.zeros(len(t), np.int8)
    for times, warnings, connected in per_battery:
        idx = np.searchsorted(times, t, side="right") - 1
        seen = idx >= 0
        latest = np.where(seen & connected[np.maximum(idx, 0)], warnings[np.maximum(idx, 0)], 0)
        worst = np.maximum(worst, latest.astype(np.int8))
    # while armed it only rises: a running maximum that starts again at every disarmed sample (where it is the
    # worst warning itself), from NONE before the first one; the group number lifts each group above the last
    armed_b = np.asarray(armed, bool)
    group = np.cumsum(~armed_b)
    value = np.where(group == 0, np.maximum(worst, 0), worst).astype(np.int64) + 128  # 0..255
    lifted = group.astype(np.int64) * 256 + value
    return np.asarray(np.maximum.accumulate(lifted) - group * 256 - 128, np.int8) if len(t) else np.zeros(0, np.int8)
