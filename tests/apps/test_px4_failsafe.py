"""PX4's battery failsafe against PX4's source, rule by rule.

Every test names the PX4-Autopilot file and function whose behaviour it pins (read at PX4/PX4-Autopilot main:
src/lib/battery/battery.cpp, src/modules/commander/HealthAndArmingChecks/checks/batteryCheck.cpp,
src/modules/commander/failsafe/failsafe.cpp, framework.cpp, framework.h, commander_params.c), and synthetic logs
cover every level and action at the thresholds' boundaries.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from px4_flights import write_px4_flight

from codegen.apps.failsafe import px4_actions as actions
from codegen.apps.failsafe.px4_actions import Action
from codegen.apps.failsafe.px4_levels import (
    Px4Level,
    Thresholds,
    battery_warnings,
    commander_warning,
    determine_warning,
    latches,
    release_of,
)
from codegen.apps.failsafe.px4_log import read_px4_log
from codegen.apps.failsafe.px4_replay import replay_px4
from codegen.apps.schemas.package import bundled_package, package_module

L, C, E, N = Px4Level.LOW, Px4Level.CRITICAL, Px4Level.EMERGENCY, Px4Level.NONE


def test_levels_are_battery_status_warning() -> None:
    """msg/BatteryStatus.msg WARNING_NONE .. WARNING_EMERGENCY (the generated enum of the bundled schema)."""
    generated = package_module(bundled_package(), "uorb").BatteryStatusWarning
    assert [int(getattr(generated, level.name)) for level in Px4Level] == [0, 1, 2, 3]


def test_defaults() -> None:
    """src/lib/battery/battery_params_common.c BAT_LOW_THR 0.15, BAT_CRIT_THR 0.07, BAT_EMERGEN_THR 0.05;
    commander_params.c COM_LOW_BAT_ACT 0, COM_FLTT_LOW_ACT 3, COM_FAIL_ACT_T 5.0."""
    assert Thresholds.from_values({}) == Thresholds(0.15, 0.07, 0.05)
    assert actions.Px4Settings.from_values({}) == actions.Px4Settings(0, 3, 5.0)
    with pytest.raises(ValueError, match="COM_LOW_BAT_ACT: expected an integer"):
        actions.Px4Settings.from_values({"COM_LOW_BAT_ACT": 1.5})
    with pytest.raises(ValueError, match="COM_LOW_BAT_ACT: expected an int32, got 1e"):
        actions.Px4Settings.from_values({"COM_LOW_BAT_ACT": 1e300})
    with pytest.raises(ValueError, match="BAT_LOW_THR: expected a finite number"):
        Thresholds.from_values({"BAT_LOW_THR": float("nan")})


@pytest.mark.parametrize(
    ("soc", "level"),
    [
        (0.15, N),  # at the threshold: not below (strict <), as float32
        (float(np.nextafter(np.float32(0.15), np.float32(0))), L),
        (0.07, L),
        (float(np.nextafter(np.float32(0.07), np.float32(0))), C),
        (0.05, C),
        (float(np.nextafter(np.float32(0.05), np.float32(0))), E),
        (0.0, E),
        (1.0, N),
    ],
)
def test_determine_warning_boundaries(soc: float, level: Px4Level) -> None:
    """battery.cpp Battery::determineWarning: `state_of_charge < _params.emergen_thr` -> EMERGENCY, else `<
    crit_thr` -> CRITICAL, else `< low_thr` -> LOW, else NONE; float32 values."""
    assert determine_warning(np.array([soc]), Thresholds())[0] == level


def test_warning_needs_a_connected_initialized_battery() -> None:
    """battery.cpp Battery::updateBatteryStatus: `_battery_initialized = _connected && (timestamp >
    _last_unconnected_timestamp + 2_s)`; `if (_connected && _battery_initialized) _warning = determineWarning(...)`."""
    boot = np.array([0.5, 1.0, 2.5, 3.0, 3.5, 4.0, 6.5])
    soc = np.full(7, 0.1)
    connected = np.array([True, True, True, False, True, True, True])
    got = battery_warnings(boot, soc, connected, Thresholds()).tolist()
    # not initialized until 2 s after boot; disconnected at 3.0 s: the warning holds, 2 s more to re-initialize
    assert got == [0, 0, 1, 1, 1, 1, 1]
    assert (
        battery_warnings(boot, np.array([0.1, 0.1, 0.1, 0.1, 0.5, 0.5, 0.5]), np.ones(7, bool), Thresholds())[-1] == N
    )  # recomputed every update since v1.12: it drops back


def test_older_releases_latch() -> None:
    """battery.cpp (v1.10/v1.11) Battery::determineWarning: "propagate warning state only if the state is higher,
    otherwise remain in current warning state"; v1.12 recomputes it (`_warning = determineWarning(...)`)."""
    boot = np.arange(3.0, 6.0, 1.0)
    soc = np.array([0.1, 0.5, 0.5])
    assert battery_warnings(boot, soc, np.ones(3, bool), Thresholds(), latched=True).tolist() == [1, 1, 1]
    assert latches((1, 11, 3)) and not latches((1, 12, 0)) and not latches(None)
    assert release_of("PX4 v1.14.0 (b8c541dd)") == (1, 14, 0) and release_of("PX4") is None


def test_commander_latches_while_armed() -> None:
    """batteryCheck.cpp BatteryChecks::checkAndReport: the worst warning of the connected batteries; "if armed, only
    allow increase of battery warning severity", else it follows."""
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    one = (t, np.array([1, 2, 0, 0, 0], np.int8), np.ones(5, bool))
    two = (t, np.array([0, 0, 1, 1, 3], np.int8), np.array([True, True, True, True, False]))  # not connected at 4 s
    armed = np.array([True, True, True, False, False])
    assert commander_warning([one, two], t, armed).tolist() == [1, 2, 2, 1, 0]


@pytest.mark.parametrize(
    ("param", "expected"),
    [
        (0, {L: Action.WARN, C: Action.WARN, E: Action.WARN}),
        (1, {L: Action.WARN, C: Action.RTL, E: Action.RTL}),
        (2, {L: Action.WARN, C: Action.LAND, E: Action.LAND}),
        (3, {L: Action.WARN, C: Action.RTL, E: Action.LAND}),
    ],
)
def test_battery_action_per_level(param: int, expected: dict[Px4Level, Action]) -> None:
    """failsafe.cpp Failsafe::fromBatteryWarningActParam (LowBatteryAction Warning 0, Return 1, Land 2,
    ReturnOrLand 3: Return at CRITICAL, Land at EMERGENCY)."""
    assert {level: actions.battery_action(param, level) for level in (L, C, E)} == expected
    assert actions.battery_action(param, N) is Action.NONE


def test_action_at_arming() -> None:
    """failsafe.cpp Failsafe::checkStateAndMode: `warning_worse_than_at_arming ? _param_com_low_bat_act.get() :
    LowBatteryAction::Warning` (PR #23784, v1.16; issue #21206: a failsafe at arming); updateArmingState keeps
    the warning at arming."""
    assert actions.acting_parameter(2, C, C, (1, 16, 0)) == 0  # armed with CRITICAL: only a warning
    assert actions.acting_parameter(2, E, C, (1, 16, 0)) == 2  # worse than at arming: the action
    assert actions.acting_parameter(2, C, C, (1, 15, 0)) == 2  # before v1.16: at once
    assert actions.acting_parameter(2, C, N, None) == 2


def test_arming_refused() -> None:
    """batteryCheck.cpp BatteryChecks::checkAndReport while disarmed: `affected_modes =
    (!configured_arm_threshold_in_use && critical_or_higher) || (configured_arm_threshold_in_use &&
    below_configured_arm_threshold) ? All : None`, in use where COM_ARM_BAT_MIN >= -FLT_EPSILON (v1.16, PR #23784);
    v1.15 (PR #22175): critical or below; v1.14: critical."""
    assert not actions.arming_refused(L, 0.1, None, (1, 14, 0)) and actions.arming_refused(C, 0.06, None, (1, 14, 0))
    assert actions.arming_refused(L, 0.3, 0.4, (1, 15, 0)) and actions.arming_refused(C, 0.06, 0.0, (1, 15, 0))
    assert not actions.arming_refused(C, 0.06, 0.05, (1, 16, 0))  # COM_ARM_BAT_MIN below the critical level: arms
    assert actions.arming_refused(N, 0.3, 0.4, (1, 16, 0)) and actions.arming_refused(C, 0.06, -1.0, (1, 16, 0))
    assert not actions.arming_refused(C, 0.06, 0.0, None)  # 0: always allows (the newest rule)


def test_remaining_flight_time() -> None:
    """batteryCheck.cpp BatteryChecks::rtlEstimateCheck: `safe_time_estimate * hysteresis_factor >=
    worst_battery_time_s`, factor 1.1 once set, armed and a finite time only; failsafe.cpp
    fromRemainingFlightTimeLowActParam: 0 None, 1 Warning, 3 Return."""
    assert actions.remaining_time_low(100.0, 100.0, True, False)
    assert not actions.remaining_time_low(100.0, 105.0, True, False) and actions.remaining_time_low(
        100.0, 105.0, True, True
    )
    assert not actions.remaining_time_low(100.0, 50.0, False, False)  # disarmed
    assert not actions.remaining_time_low(100.0, float("nan"), True, False)  # no estimate: no condition
    assert actions.remaining_time_low(100.0, 0.0, True, False)  # a time of 0 is finite: taken as valid (issue #27929)
    assert [actions.flight_time_action(v) for v in (0, 1, 2, 3)] == [Action.NONE, Action.WARN, Action.NONE, Action.RTL]


def test_remaining_time_over_a_flight() -> None:
    """batteryCheck.cpp rtlEstimateCheck: the estimate must be valid and younger than 3 s; the worst finite
    time_remaining_s of the connected batteries (checkAndReport's worst_battery_time_s); 1.1 to clear."""
    t = np.arange(0.0, 8.0)
    estimate = (np.array([0.0, 4.0]), np.array([100.0, np.nan]))  # valid at 0 s, not valid from 4 s
    one = (t, np.array([200.0, 150.0, 105.0, 99.0, 95.0, 90.0, 90.0, 90.0]), np.ones(8, bool))
    two = (t, np.full(8, 50.0), np.zeros(8, bool))  # not connected: not counted
    flags = actions.remaining_time_flags(t, estimate, [one, two], np.ones(8, bool))
    # 99 s <= 100 s at 3 s; the estimate is 3 s old at 3 s (not younger than 3 s): off; from 4 s not valid
    assert flags.tolist() == [False, False, False, False, False, False, False, False]
    estimate = (t, np.full(8, 100.0))
    flags = actions.remaining_time_flags(t, estimate, [one, two], np.ones(8, bool))
    assert flags.tolist() == [False, False, False, True, True, True, True, True]
    back = (t, np.array([200.0, 99.0, 105.0, 111.0, 105.0, 90.0, 90.0, 90.0]), np.ones(8, bool))
    flags = actions.remaining_time_flags(t, estimate, [back], np.ones(8, bool))
    assert flags.tolist() == [False, True, True, False, False, True, True, True]  # 105 < 110 holds, 111 clears
    armed = np.array([True, True, False, False, True, True, True, True])
    assert not actions.remaining_time_flags(t, estimate, [back], armed)[2]


def test_selection_and_modes() -> None:
    """framework.cpp FailsafeBase::getSelectedAction: None while disarmed, else the most severe (framework.h Action:
    None, Warn, FallbackPosCtrl, FallbackAltCtrl, FallbackStab, Hold, RTL, Land); checkFailsafe: Auto takeover waits
    COM_FAIL_ACT_T in Hold where it is above 0.1 s; modeFromAction: AUTO_LOITER 4, AUTO_RTL 5, AUTO_LAND 18."""
    assert (Action.WARN, Action.HOLD, Action.RTL, Action.LAND) == (1, 5, 6, 7)
    assert actions.selected([Action.WARN, Action.LAND, Action.RTL], armed=True) is Action.LAND
    assert actions.selected([Action.LAND], armed=False) is Action.NONE
    assert actions.Px4Settings(fail_act_t=0.1).delay_s == 0.0 and actions.Px4Settings(fail_act_t=5).delay_s == 5.0
    assert actions.NAV_STATES == {Action.HOLD: 4, Action.RTL: 5, Action.LAND: 18}


# -- synthetic logs: every level and action at the boundaries


def _f32_below(x: float) -> float:
    return float(np.nextafter(np.float32(x), np.float32(0)))


DESCENT = [0.5, 0.15, _f32_below(0.15), 0.07, _f32_below(0.07), 0.05, _f32_below(0.05), 0.0]
LEVELS = [0, 0, 1, 1, 2, 2, 3, 3]


@pytest.mark.parametrize(
    ("param", "actions", "outcomes"),
    [
        (0, ["WARN", "WARN", "WARN"], ["warn", "warn", "warn"]),
        (1, ["WARN", "RTL", "RTL"], ["warn", "hold 5s, then rtl", "hold 5s, then rtl"]),
        (2, ["WARN", "LAND", "LAND"], ["warn", "hold 5s, then land", "hold 5s, then land"]),
        (3, ["WARN", "RTL", "LAND"], ["warn", "hold 5s, then rtl", "hold 5s, then land"]),
    ],
)
def test_synthetic_log_every_level_and_action(
    tmp_path: Path, param: int, actions: list[str], outcomes: list[str]
) -> None:
    log = write_px4_flight(tmp_path / "f.ulg", DESCENT, warnings=LEVELS, flags=[(0.4, 1), (0.8, 2), (1.2, 3)])
    replay = replay_px4(read_px4_log(log), {"COM_LOW_BAT_ACT": param})
    assert [(e.level, round(e.time - 10, 3)) for e in replay.events] == [(L, 0.4), (C, 0.8), (E, 1.2)]
    assert [e.action.name for e in replay.events] == actions
    assert [e.outcome for e in replay.events] == outcomes
    assert [e.threshold for e in replay.events] == [0.15, 0.07, 0.05]
    battery, flags = replay.checks[0], replay.checks[1]
    assert battery.ok and [c.value for c in battery.replayed] == [1, 2, 3]
    assert flags.ok and [c.value for c in flags.logged] == [1, 2, 3]


def test_synthetic_log_differs_and_disarmed_ground(tmp_path: Path) -> None:
    # a log whose firmware logged LOW one sample late still matches; two samples late does not
    late = write_px4_flight(tmp_path / "late.ulg", DESCENT[:4], warnings=[0, 0, 0, 1])
    assert replay_px4(read_px4_log(late)).checks[0].ok
    later = write_px4_flight(tmp_path / "later.ulg", [0.5, 0.1, 0.1, 0.1], warnings=[0, 0, 0, 1])
    check = replay_px4(read_px4_log(later)).checks[0]
    assert not check.ok and "logged at" in check.problems[0]
    # on the ground: the level is computed, commander acts on nothing (getSelectedAction: None while disarmed)
    ground = write_px4_flight(tmp_path / "ground.ulg", DESCENT, warnings=LEVELS, armed=None)
    replay = replay_px4(read_px4_log(ground), {"COM_LOW_BAT_ACT": 2})
    assert replay.events == [] and replay.checks[0].ok
    assert "does not record failsafe_flags" in replay.checks[1].undecided


def test_synthetic_log_arming_with_a_critical_battery(tmp_path: Path) -> None:
    # armed at 1 s with CRITICAL already: a warning (v1.16's rule); EMERGENCY later is worse: its action
    soc = [0.06] * 10 + [0.04] * 5
    log = write_px4_flight(tmp_path / "arm.ulg", soc, armed=(1.0, 1e9), nav=[(2.5, 18)])
    replay = replay_px4(read_px4_log(log), {"COM_LOW_BAT_ACT": 2, "COM_FAIL_ACT_T": 0})
    assert [(e.level, e.action) for e in replay.events] == [(C, Action.WARN), (E, Action.LAND)]
    action = replay.checks[-1]
    assert action.ok and action.replayed[0].value == 18  # vehicle_status.nav_state AUTO_LAND, as logged
    # the log's release is unknown (the newest rules): without COM_ARM_BAT_MIN, arming at CRITICAL is refused
    arming = next(c for c in replay.checks if c.what == "arming with the battery's level")
    assert "armed at 11.000s with CRITICAL, 0.060 left: the battery check refuses" in arming.problems[0]
    allowed = replay_px4(read_px4_log(log), {"COM_LOW_BAT_ACT": 2, "COM_ARM_BAT_MIN": 0.05})
    assert next(c for c in allowed.checks if c.what == "arming with the battery's level").ok
