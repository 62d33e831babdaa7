"""PX4 commander's reaction to the battery warning and to a low remaining flight time (the failsafe framework, v1.14+).

From PX4-Autopilot's ``src/modules/commander/failsafe/`` (each rule pinned in ``tests/apps/test_px4_failsafe.py``):

- ``failsafe.cpp`` ``Failsafe::fromBatteryWarningActParam``: LOW only warns ("Low battery level, return advised");
  CRITICAL warns, or with ``COM_LOW_BAT_ACT`` 1 (Return) / 3 (Return or Land) returns, with 2 lands; EMERGENCY
  warns, or with 1 returns, with 2 or 3 lands;
- ``Failsafe::checkStateAndMode``: the action is the parameter's only while the warning is worse than it was at
  arming (``_battery_warning_at_arming``, from ``updateArmingState``), else a warning: arming with a low battery
  that ``COM_ARM_BAT_MIN`` allowed does not fail at once (PR #23784, v1.16; earlier releases acted at once);
- ``batteryCheck.cpp`` ``BatteryChecks::checkAndReport`` refuses arming (a failure in every mode) with a CRITICAL or
  worse warning; from v1.16, where ``COM_ARM_BAT_MIN`` is set (0 or more), instead exactly when the worst state of
  charge is below it (PR #23784; v1.15 refused below it as well as at CRITICAL); a LOW warning never refuses;
- ``Failsafe::fromRemainingFlightTimeLowActParam``: ``COM_FLTT_LOW_ACT`` 0 nothing, 1 warns, 3 returns, for
  ``battery_low_remaining_time``, which ``batteryCheck.cpp`` ``BatteryChecks::rtlEstimateCheck`` sets while armed
  when the RTL estimate's safe time is at least the worst battery's ``time_remaining_s`` (x 1.1 once set: the way
  out is harder than the way in), a finite time only;
- ``framework.cpp`` ``FailsafeBase::getSelectedAction``: nothing while disarmed; the most severe action wins
  (``framework.h`` ``Action``: None, Warn, three fallbacks, Hold, RTL, Land, ...); ``inFailsafe`` is any action
  but None, so a warning sets ``vehicle_status.failsafe`` too; an
  action other than a warning waits ``COM_FAIL_ACT_T`` seconds in Hold first (``UserTakeoverAllowed::Auto``, the
  battery's actions' default, in ``checkFailsafe``), where the parameter is above 0.1 s.

The battery's rules are the same for every vehicle type: ``checkStateAndMode`` has no vehicle-type branch for them.

Parameter defaults (``src/modules/commander/commander_params.c`` / ``module.yaml``): ``COM_LOW_BAT_ACT`` 0 (warning),
``COM_FLTT_LOW_ACT`` 3 (return), ``COM_FAIL_ACT_T`` 5 s, ``COM_ARM_BAT_MIN`` -1 (not used; v1.15: 0).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..battery.columns import NDArray
from .px4_levels import Px4Level

FLT_EPSILON = 1.1920928955078125e-07
HYSTERESIS = 1.1  # batteryCheck.cpp rtlEstimateCheck: hysteresis_factor once battery_low_remaining_time is set
ESTIMATE_MAX_AGE_S = 3.0  # rtlEstimateCheck: an rtl_time_estimate older than 3 s is not used
AT_ARMING_FROM = (1, 16)  # PR #23784: the action only for a warning worse than at arming
INT32 = (-(2**31), 2**31 - 1)
DEFAULTS: dict[str, float] = {"COM_LOW_BAT_ACT": 0, "COM_FLTT_LOW_ACT": 3, "COM_FAIL_ACT_T": 5.0}
LOW_BAT_ACTIONS = {0: "Warning", 1: "Return", 2: "Land", 3: "Return or Land"}  # failsafe.h LowBatteryAction
FLTT_ACTIONS = {0: "None", 1: "Warning", 3: "Return"}  # command_after_remaining_flight_time_low


class Action(enum.IntEnum):
    """framework.h ``FailsafeBase::Action``, in its order of severity (the subset the battery uses)."""

    NONE = 0
    WARN = 1
    HOLD = 5
    RTL = 6
    LAND = 7


# vehicle_status.nav_state a mode action puts the vehicle in (NAVIGATION_STATE_AUTO_LOITER / _AUTO_RTL / _AUTO_LAND)
NAV_STATES = {Action.HOLD: 4, Action.RTL: 5, Action.LAND: 18}

TEXTS = {  # framework.cpp notifyUser, the battery causes with a warning
    Px4Level.LOW: "Low battery level, return advised",
    Px4Level.CRITICAL: "Critical battery level, land now",
    Px4Level.EMERGENCY: "Emergency battery level, land immediately",
}
FLIGHT_TIME_TEXT = "Low remaining flight time, return advised"


@dataclass(frozen=True)
class Px4Settings:
    """The commander parameters of the battery failsafe."""

    low_bat_act: int = 0
    fltt_low_act: int = 3
    fail_act_t: float = 5.0

    @classmethod
    def from_values(cls, values: Mapping[str, float]) -> Px4Settings:
        def code(name: str) -> int:
            value = values.get(name, DEFAULTS[name])
            if isinstance(value, bool) or not isinstance(value, int | float) or not float(value).is_integer():
                raise ValueError(f"{name}: expected an integer, got {value!r}")
            if not INT32[0] <= value <= INT32[1]:  # PX4 holds it as an int32 parameter
                raise ValueError(f"{name}: expected an int32, got {value:g}")
            return int(value)

        delay = values.get("COM_FAIL_ACT_T", DEFAULTS["COM_FAIL_ACT_T"])
        if isinstance(delay, bool) or not isinstance(delay, int | float) or not math.isfinite(delay):
            raise ValueError(f"COM_FAIL_ACT_T: expected a finite number, got {delay!r}")
        return cls(code("COM_LOW_BAT_ACT"), code("COM_FLTT_LOW_ACT"), float(delay))

    @property
    def delay_s(self) -> float:
        """The Hold before a mode action (``checkFailsafe``: only where COM_FAIL_ACT_T > 0.1)."""
        return self.fail_act_t if self.fail_act_t > 0.1 else 0.0


def battery_action(low_bat_act: int, warning: Px4Level) -> Action:
    """``Failsafe::fromBatteryWarningActParam``."""
    if warning is Px4Level.LOW:
        return Action.WARN
    if warning is Px4Level.CRITICAL:
        return {1: Action.RTL, 3: Action.RTL, 2: Action.LAND}.get(low_bat_act, Action.WARN)
    if warning is Px4Level.EMERGENCY:
        return {1: Action.RTL, 2: Action.LAND, 3: Action.LAND}.get(low_bat_act, Action.WARN)
    return Action.NONE


def acting_parameter(
    low_bat_act: int, warning: Px4Level, at_arming: Px4Level, release: tuple[int, int, int] | None
) -> int:
    """``Failsafe::checkStateAndMode``: the COM_LOW_BAT_ACT in effect; 0 (warning) for a warning no worse than at
    arming, from v1.16 (an unknown release: the newest rule)."""
    newer = release is None or release[:2] >= AT_ARMING_FROM
    return low_bat_act if not newer or warning > at_arming else 0


def arming_refused(
    warning: Px4Level, worst_remaining: float, arm_bat_min: float | None, release: tuple[int, int, int] | None
) -> bool:
    """``BatteryChecks::checkAndReport`` while disarmed: whether the battery check fails arming (``arm_bat_min``:
    COM_ARM_BAT_MIN, None where the log has none). An unknown release: the newest rule."""
    critical = warning >= Px4Level.CRITICAL
    if arm_bat_min is None:
        return critical
    below = worst_remaining < arm_bat_min
    if release is not None and release[:2] < AT_ARMING_FROM:
        return critical or below
    in_use = arm_bat_min >= -FLT_EPSILON
    return below if in_use else critical


def flight_time_action(fltt_low_act: int) -> Action:
    """``Failsafe::fromRemainingFlightTimeLowActParam`` (any other value: nothing)."""
    return {1: Action.WARN, 3: Action.RTL}.get(fltt_low_act, Action.NONE)


def remaining_time_low(safe_time_s: float, worst_time_s: float, armed: bool, already: bool) -> bool:
    """``BatteryChecks::rtlEstimateCheck``: the flight time left no longer covers the way home."""
    factor = HYSTERESIS if already else 1.0
    return armed and math.isfinite(worst_time_s) and safe_time_s * factor >= worst_time_s


def remaining_time_flags(
    t: NDArray,
    estimate: tuple[NDArray, NDArray],
    per_battery: list[tuple[NDArray, NDArray, NDArray]],
    armed: NDArray,
) -> NDArray:
    """``battery_low_remaining_time`` at each of the times ``t`` (``rtlEstimateCheck``): ``estimate`` is
    rtl_time_estimate's (times, safe time, NaN where not valid); ``per_battery`` each battery's (times,
    time_remaining_s, connected): the worst finite time of the connected batteries is compared."""
    est_t, safe = estimate
    k = np.searchsorted(est_t, t, side="right") - 1
    fresh = (k >= 0) & (t - est_t[np.maximum(k, 0)] < ESTIMATE_MAX_AGE_S)
    safe_now = np.where(fresh, safe[np.maximum(k, 0)], np.nan)
    worst = np.full(len(t), np.inf)
    for times, left, connected in per_battery:
        j = np.searchsorted(times, t, side="right") - 1
        ok = (j >= 0) & connected[np.maximum(j, 0)] & np.isfinite(left[np.maximum(j, 0)])
        worst = np.where(ok, np.minimum(worst, left[np.maximum(j, 0)]), worst)
    worst = np.where(np.isinf(worst), np.nan, worst)
    out = np.zeros(len(t), bool)
    flag = False
    for i, (s, w, a) in enumerate(zip(safe_now.tolist(), worst.tolist(), armed.tolist(), strict=True)):
        flag = s == s and remaining_time_low(s, w, a, flag)  # NaN: no valid, fresh estimate
        out[i] = flag
    return out


def selected(actions: list[Action], armed: bool) -> Action:
    """``FailsafeBase::getSelectedAction``: nothing while disarmed, else the most severe."""
    return max(actions, default=Action.NONE) if armed else Action.NONE
