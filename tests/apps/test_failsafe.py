"""The battery failsafe evaluator: the seed's (AN-00035) scenarios, pinned."""

from __future__ import annotations

import dataclasses

import pytest

from codegen.apps.failsafe.evaluator import (
    DEFAULTS,
    Action,
    BatteryFailsafe,
    BatteryReading,
    Cause,
    Event,
    FailsafeSettings,
    Level,
    Outcome,
    resolve_action,
)
from codegen.apps.failsafe.levels import apply_level

# a 3S LiPo as in the seed: LOW 10.5 V (3.5 V/cell), CRITICAL 10.0 V; LOW -> RTL, CRITICAL -> Hold
PARAMS = FailsafeSettings(low_volt=10.5, crt_volt=10.0, low_action=Action.RTL, crt_action=Action.HOLD)


def run(fs: BatteryFailsafe, volts: list[tuple[float, float]], **kw: object) -> list[Event]:
    out: list[Event] = []
    for t, v in volts:
        out += fs.update(t, BatteryReading(voltage_v=v), armed=True, **kw)  # type: ignore[arg-type]
    return out


def level(fs: BatteryFailsafe) -> Level:
    return fs.level  # a call, so mypy does not narrow the attribute between updates


def series(start: float, end: float, volts: float, step: float = 1.0) -> list[tuple[float, float]]:
    n = round((end - start) / step)
    return [(start + i * step, volts) for i in range(n + 1)]


def test_sag_shorter_than_the_timer_does_not_trigger() -> None:
    fs = BatteryFailsafe(PARAMS)
    samples = series(0, 5, 11.5) + series(6, 14, 10.3) + series(15, 40, 11.4)  # 9 s below 10.5 V
    assert run(fs, samples) == []
    assert level(fs) is Level.NONE


def test_sustained_sag_triggers_low_at_exactly_the_timer() -> None:
    fs = BatteryFailsafe(PARAMS)
    events = run(fs, series(0, 4, 11.5) + series(5, 30, 10.4))
    assert len(events) == 1
    e = events[0]
    assert e.time == 15.0  # below from t=5, BATT_LOW_TIMER 10 s
    assert (e.level, e.cause, e.value, e.threshold) == (Level.LOW, Cause.VOLTAGE, 10.4, 10.5)
    assert (e.action, e.outcome) == (Action.RTL, Outcome.RTL)
    assert e.text == "Battery LOW: 10.4V"


def test_timer_follows_batt_low_timer_and_fine_samples() -> None:
    fs = BatteryFailsafe(dataclasses.replace(PARAMS, low_timer_s=3))
    events = run(fs, series(0.0, 10.0, 10.4, step=0.1))
    assert [round(e.time, 6) for e in events] == [3.0]


def test_critical_is_immediate_and_overrides_low() -> None:
    fs = BatteryFailsafe(PARAMS)
    events = run(fs, [(0, 11.5), (1, 10.4)])
    assert events == []
    events = run(fs, [(2, 9.8)])
    assert len(events) == 1
    e = events[0]
    assert (e.time, e.level, e.cause, e.threshold, e.action, e.outcome) == (
        2,
        Level.CRITICAL,
        Cause.VOLTAGE,
        10.0,
        Action.HOLD,
        Outcome.HOLD,
    )
    assert e.text == "Battery CRITICAL: 9.8V"
    assert run(fs, series(3, 30, 9.8)) == []  # no LOW after CRITICAL: levels only escalate


def test_recovery_does_not_clear_low_or_critical() -> None:
    fs = BatteryFailsafe(PARAMS)
    run(fs, series(0, 10, 10.4))
    assert level(fs) is Level.LOW
    assert run(fs, series(11, 60, 12.0)) == []  # voltage recovers under less load
    assert level(fs) is Level.LOW
    run(fs, [(61, 9.5)])
    assert level(fs) is Level.CRITICAL
    assert run(fs, series(62, 100, 12.4)) == []
    assert level(fs) is Level.CRITICAL


def test_disarm_clears_and_nothing_triggers_while_disarmed() -> None:
    fs = BatteryFailsafe(PARAMS)
    run(fs, [(0, 9.0)])
    assert level(fs) is Level.CRITICAL
    cleared = fs.update(1, BatteryReading(voltage_v=9.0), armed=False)
    assert [(e.level, e.cause) for e in cleared] == [(Level.NONE, Cause.DISARMED)]
    for t in range(2, 30):
        assert fs.update(t, BatteryReading(voltage_v=9.0), armed=False) == []
    assert level(fs) is Level.NONE


def test_zero_voltage_is_unknown_and_zero_threshold_is_disabled() -> None:
    fs = BatteryFailsafe(PARAMS)
    assert run(fs, series(0, 60, 0.0)) == []
    fs = BatteryFailsafe(FailsafeSettings(low_volt=0, crt_volt=0))
    assert run(fs, series(0, 60, 1.0)) == []
    fs = BatteryFailsafe(PARAMS)
    # a dropout (0 V) in the middle of a sag restarts the timer
    assert run(fs, [*series(0, 6, 10.4), (7, 0.0), *series(8, 16, 10.4)]) == []
    assert [e.time for e in run(fs, [(17, 10.4), (18, 10.4)])] == [18]


def test_capacity_thresholds_use_capacity_minus_consumed() -> None:
    params = FailsafeSettings(capacity_mah=3300, low_mah=660, crt_mah=330, low_action=Action.RTL)
    fs = BatteryFailsafe(params)
    events: list[Event] = []
    for t, consumed in [(0, 100.0), (1, 2600.0), (2, 2700.0), (3, 2900.0), (4, 3000.0)]:
        events += fs.update(t, BatteryReading(voltage_v=11.0, consumed_mah=consumed), armed=True)
    assert [(e.time, e.level, e.cause, e.value) for e in events] == [
        (2, Level.LOW, Cause.CAPACITY, 600.0),
        (4, Level.CRITICAL, Cause.CAPACITY, 300.0),
    ]
    assert events[0].text == "Battery LOW: 600mAh"


def test_capacity_from_integrated_current() -> None:
    params = FailsafeSettings(capacity_mah=1000, low_mah=500)
    fs = BatteryFailsafe(params)
    events: list[Event] = []
    for t in range(0, 1000):  # 3.6 A = 1 mAh per second
        events += fs.update(float(t), BatteryReading(voltage_v=11.0, current_a=3.6), armed=True)
    assert [e.time for e in events] == [501.0]  # 501 mAh consumed, 499 left


def test_rtl_without_home_falls_back_to_hold() -> None:
    fs = BatteryFailsafe(PARAMS, home_set=False)
    events = run(fs, series(0, 10, 10.4))
    assert [(e.action, e.outcome) for e in events] == [(Action.RTL, Outcome.HOLD)]
    fs = BatteryFailsafe(PARAMS)
    events = run(fs, series(0, 10, 10.4), position_fix=False)
    assert [(e.action, e.outcome) for e in events] == [(Action.RTL, Outcome.HOLD)]


@pytest.mark.parametrize(
    ("action", "home", "fix", "smart", "expected"),
    [
        (Action.NONE, True, True, True, Outcome.NONE),
        (Action.HOLD, True, True, True, Outcome.HOLD),
        (Action.RTL, True, True, True, Outcome.RTL),
        (Action.RTL, False, True, True, Outcome.HOLD),
        (Action.SMART_RTL, True, True, True, Outcome.SMART_RTL),
        (Action.SMART_RTL, True, True, False, Outcome.RTL),
        (Action.SMART_RTL, False, True, False, Outcome.HOLD),
        (Action.SMART_RTL_OR_HOLD, True, True, True, Outcome.SMART_RTL),
        (Action.SMART_RTL_OR_HOLD, True, True, False, Outcome.HOLD),  # skips RTL
        (Action.TERMINATE, False, False, False, Outcome.DISARM),
    ],
)
def test_fallback_chain(action: Action, home: bool, fix: bool, smart: bool, expected: Outcome) -> None:
    assert resolve_action(action, home_set=home, position_fix=fix, smart_rtl_ready=smart) is expected


def test_terminate_disarms_until_the_stream_rearms() -> None:
    fs = BatteryFailsafe(FailsafeSettings(crt_volt=10.0, crt_action=Action.TERMINATE))
    events = run(fs, [(0, 9.0)])
    assert [e.outcome for e in events] == [Outcome.DISARM]
    assert run(fs, series(1, 10, 9.0)) == []  # disarmed by the failsafe: silent
    assert fs.update(11, BatteryReading(voltage_v=9.0), armed=False) == []
    assert [e.level for e in run(fs, [(12, 9.0)])] == [Level.CRITICAL]  # re-armed: a new flight


def drive_out(fs: BatteryFailsafe, *, speed: float = 2.0, amps: float = 2.0) -> list[tuple[float, float, Event]]:
    """A rover driving straight away from home at constant speed and current."""
    out = []
    for t in range(0, 4000):
        d = speed * t
        for e in fs.update(float(t), BatteryReading(voltage_v=11.5, current_a=amps), armed=True, distance_to_home_m=d):
            out.append((float(t), d, e))
    return out


def test_distance_rule_triggers_before_the_point_of_no_return() -> None:
    params = FailsafeSettings(capacity_mah=3300, low_action=Action.RTL)
    fs = BatteryFailsafe(params)
    fired = drive_out(fs)
    assert len(fired) == 1
    t, d, e = fired[0]
    assert (e.level, e.cause, e.outcome) == (Level.LOW, Cause.DISTANCE, Outcome.RTL)
    rate = 2.0 * 1000 / 3600 / 2.0  # mAh per metre, learned from the samples
    remaining = 3300 - 2.0 * t * 1000 / 3600
    point_of_no_return = 3300 / (2 * rate * 2.0)  # seconds until remaining == distance * rate
    assert t < point_of_no_return
    assert e.value == pytest.approx(remaining, rel=1e-6)
    assert remaining >= d * rate * 1.3 * 0.999  # still enough to return, with the margin
    assert remaining < (d + 2.0) * rate * 1.3  # and triggered as soon as that stopped holding a second later
    assert e.threshold == pytest.approx(d * rate * 1.3, rel=1e-3)
    assert e.text.startswith("Battery LOW: ") and "needed to return" in e.text


def test_distance_rule_margin_and_no_current_sensor() -> None:
    early = drive_out(BatteryFailsafe(FailsafeSettings(capacity_mah=3300), margin=2.0))
    late = drive_out(BatteryFailsafe(FailsafeSettings(capacity_mah=3300), margin=1.0))
    assert early[0][0] < late[0][0]
    fs = BatteryFailsafe(FailsafeSettings(capacity_mah=3300))
    for t in range(0, 4000):  # voltage only: nothing to learn a rate from, no remaining charge
        assert fs.update(float(t), BatteryReading(voltage_v=11.5), armed=True, distance_to_home_m=2.0 * t) == []


def test_levels_map_onto_uorb_warning_and_mavlink_charge_state() -> None:
    from generated.mavlink import MavBatteryChargeState
    from generated.uorb import BatteryStatusWarning

    fs = BatteryFailsafe(PARAMS)
    low = run(fs, series(0, 10, 10.4))[0]
    crit = run(fs, [(11, 9.0)])[0]
    assert low.uorb_warning == BatteryStatusWarning.LOW and crit.uorb_warning == BatteryStatusWarning.CRITICAL
    assert low.mavlink_charge_state == MavBatteryChargeState.LOW
    assert crit.mavlink_charge_state == MavBatteryChargeState.CRITICAL
    assert apply_level("uorb.BatteryStatus", {"voltage_v": 9.0}, Level.CRITICAL) == {"voltage_v": 9.0, "warning": 2}
    assert apply_level("mavlink.BATTERY_STATUS", {}, Level.NONE) == {"charge_state": MavBatteryChargeState.OK}


def test_params_from_values_and_schema_defaults() -> None:
    from generated.params import BattParams

    defaults = BattParams().to_dict()
    assert {k: defaults[k] for k in DEFAULTS} == DEFAULTS
    p = FailsafeSettings.from_values({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 3, "OTHER": 1})
    assert (p.low_volt, p.low_action, p.low_timer_s, p.capacity_mah) == (10.5, Action.SMART_RTL, 10.0, 3300.0)
    with pytest.raises(ValueError, match=r"BATT_FS_CRT_ACT: expected an action 0\.\.5"):
        FailsafeSettings.from_values({"BATT_FS_CRT_ACT": 9})
    with pytest.raises(ValueError, match="BATT_LOW_VOLT: expected a finite number"):
        FailsafeSettings.from_values({"BATT_LOW_VOLT": "x"})


def test_time_must_not_go_back() -> None:
    fs = BatteryFailsafe(PARAMS)
    fs.update(5, BatteryReading(voltage_v=11.0), armed=True)
    with pytest.raises(ValueError, match="never go back"):
        fs.update(4, BatteryReading(voltage_v=11.0), armed=True)


@pytest.mark.parametrize(
    ("qualified", "module", "cls", "data"),
    [
        ("uorb.BatteryStatus", "uorb", "BatteryStatus", {"voltage_v": 10.4, "current_a": 2.0, "discharged_mah": 100}),
        (
            "mavlink.BATTERY_STATUS",
            "mavlink",
            "BatteryStatus",
            {"voltages": [3500, 3500, 3400, *[65535] * 7], "current_battery": 200, "current_consumed": 100},
        ),
        ("uorb.BatteryStatus", "uorb", "BatteryStatus", {}),  # all unknown
    ],
)
def test_converters_and_ir_fallback_agree(qualified: str, module: str, cls: str, data: dict[str, object]) -> None:
    import importlib

    from codegen.apps.failsafe.stream import battery_state, battery_state_from_ir

    model = getattr(importlib.import_module(f"generated.{module}"), cls).from_dict(data)
    ours, theirs = battery_state_from_ir(qualified, model), battery_state(qualified, model)
    for name in ("voltage_v", "current_a", "consumed_mah"):
        a, b = getattr(ours, name), getattr(theirs, name)
        assert (a is None and b is None) or a == pytest.approx(b), name
