"""The battery failsafe against ArduPilot's source, item by item (issue 13, items 1-9).

Every test names the ArduPilot file and function whose behaviour it pins (read at ArduPilot/ardupilot
master: libraries/AP_BattMonitor/, Rover/, ArduCopter/, ArduPlane/, ArduSub/).
"""

from __future__ import annotations

import importlib

import pytest

from codegen.apps.failsafe.checks import check_settings
from codegen.apps.failsafe.evaluator import BatteryFailsafe, BatteryReading, Event, Level, make_failsafe
from codegen.apps.failsafe.levels import MAVLINK_CHARGE_STATE, UORB_WARNING, apply_level
from codegen.apps.failsafe.monitor import ResistanceEstimator
from codegen.apps.failsafe.settings import BatterySettings, battery_settings, prefix, split_name
from codegen.apps.failsafe.vehicles import VEHICLES, Situation, detect_vehicle

ROVER, COPTER, PLANE, SUB = (VEHICLES[n] for n in ("rover", "copter", "plane", "sub"))


def fs_for(values: dict[str, float], vehicle: str = "rover", **kw: object) -> BatteryFailsafe:
    v = VEHICLES[vehicle]
    return make_failsafe(battery_settings(values, v), v, **kw)  # type: ignore[arg-type]


def feed(fs: BatteryFailsafe, rows: list[tuple[float, float]], instance: int = 1, **kw: object) -> list[Event]:
    out: list[Event] = []
    for t, volts in rows:
        out += fs.update(t, BatteryReading(voltage_v=volts), armed=True, instance=instance, **kw)  # type: ignore[arg-type]
    return out


def steps(start: float, end: float, volts: float, step: float = 0.1) -> list[tuple[float, float]]:
    n = round((end - start) / step)
    return [(round(start + i * step, 3), volts) for i in range(n + 1)]


# -- item 1: action tables per vehicle


@pytest.mark.parametrize(
    ("vehicle", "low", "critical"),
    [
        ("rover", {0: "None", 1: "RTL", 2: "Hold", 3: "SmartRTL", 4: "SmartRTL or Hold", 5: "Terminate"}, None),
        (
            "copter",
            {
                0: "None",
                1: "Land",
                2: "RTL",
                3: "SmartRTL or RTL",
                4: "SmartRTL or Land",
                5: "Terminate",
                6: "Auto DO_LAND_START or RTL",
            },
            None,
        ),
        (
            "plane",
            {0: "None", 1: "RTL", 2: "Land", 3: "Terminate", 4: "QLand", 6: "Loiter to QLand"},
            {0: "None", 1: "RTL", 2: "Land", 3: "Terminate", 4: "QLand", 5: "Parachute", 6: "Loiter to QLand"},
        ),
        ("sub", {0: "None", 2: "Disarm", 3: "Enter surface mode"}, None),
    ],
)
def test_action_tables(vehicle: str, low: dict[int, str], critical: dict[int, str] | None) -> None:
    """AP_BattMonitor_Params.cpp, var_info: @Values{Rover|Copter|Plane|Sub} of FS_LOW_ACT / FS_CRT_ACT."""
    v = VEHICLES[vehicle]
    assert dict(v.low_actions) == low
    assert dict(v.critical_actions) == (critical or low)


def test_a_rover_file_with_low_action_1_means_rtl() -> None:
    """Rover/Rover.h enum Failsafe_Action (RTL = 1) and Rover/failsafe.cpp handle_battery_failsafe."""
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 1})
    [event] = feed(fs, steps(0, 11, 10.4, 1.0))
    assert (event.action, event.action_code, event.outcome) == ("RTL", 1, "rtl")
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 1}, "copter")
    assert feed(fs, steps(0, 11, 10.4, 1.0))[0].action == "Land"  # ArduCopter/Copter.h FailsafeAction::LAND = 1


@pytest.mark.parametrize(
    ("vehicle", "priorities"),
    [
        ("rover", (5, 2, 1, 4, 3, 0)),  # Terminate, Hold, RTL, SmartRTL_Hold, SmartRTL, None
        ("copter", (5, 1, 2, 4, 3, 0)),  # TERMINATE, LAND, RTL, SMARTRTL_LAND, SMARTRTL, NONE
        ("plane", (3, 5, 4, 2, 1, 0)),  # Terminate, Parachute, QLand, Land, RTL, None
        ("sub", (2, 3, 1, 0)),  # Disarm, Surface, Warn, None
    ],
)
def test_priority_lists(vehicle: str, priorities: tuple[int, ...]) -> None:
    """_failsafe_priorities in Rover/Rover.h, ArduCopter/Copter.h, ArduPlane/Plane.h, ArduSub/Sub.h;
    AP_BattMonitor.cpp check_failsafes: an action missing from the list gets the sentinel's index."""
    v = VEHICLES[vehicle]
    assert v.priorities == priorities
    assert [v.priority(code) for code in priorities] == list(range(len(priorities)))
    assert v.priority(99) == len(priorities)
    assert COPTER.priority(6) == 6  # AUTO_DO_LAND_START is not on Copter's list: below None


@pytest.mark.parametrize(
    ("vehicle", "code", "situation", "outcome"),
    [
        ("rover", 3, Situation(), "smart_rtl"),
        ("rover", 3, Situation(smart_rtl_ready=False), "rtl"),
        ("rover", 3, Situation(home_set=False), "hold"),
        ("rover", 4, Situation(smart_rtl_ready=False), "hold"),  # SmartRTL_Hold skips RTL
        ("rover", 5, Situation(), "disarm"),
        ("copter", 2, Situation(position_fix=False), "land"),  # set_mode_RTL_or_land_with_pause
        ("copter", 3, Situation(smart_rtl_ready=False), "rtl"),  # set_mode_SmartRTL_or_RTL
        ("copter", 4, Situation(smart_rtl_ready=False), "land"),  # set_mode_SmartRTL_or_land_with_pause
        ("copter", 6, Situation(landing_sequence=True), "auto_land"),
        ("copter", 6, Situation(), "rtl"),
        ("plane", 6, Situation(quadplane=True), "loiter_qland"),
        ("plane", 6, Situation(), "rtl"),  # Loiter to QLand -> QLand -> Land -> RTL without a QuadPlane
        ("plane", 2, Situation(landing_sequence=True), "auto_land"),
        ("plane", 5, Situation(), "parachute"),
        ("sub", 3, Situation(), "surface"),
        ("sub", 2, Situation(), "disarm"),
        ("rover", 9, Situation(), "none"),  # no case in the handler's switch
    ],
)
def test_fallback_chains(vehicle: str, code: int, situation: Situation, outcome: str) -> None:
    """Rover/failsafe.cpp handle_battery_failsafe, ArduCopter/events.cpp do_failsafe_action,
    ArduPlane/events.cpp handle_battery_failsafe, ArduSub/failsafe.cpp handle_battery_failsafe."""
    assert VEHICLES[vehicle].resolve(code, situation) == outcome


def test_vehicle_detection() -> None:
    """Parameters only one vehicle has (e.g. SURFACE_DEPTH: ArduSub/Parameters.cpp; Q_ENABLE: ArduPlane)."""
    assert detect_vehicle({"SURFACE_DEPTH": -10, "BATT_LOW_VOLT": 0}).vehicle is SUB
    assert "detected from Q_ENABLE" in detect_vehicle({"Q_ENABLE": 1}).how
    assert detect_vehicle({"CRUISE_SPEED": 2}).vehicle is ROVER
    fallback = detect_vehicle({"BATT_LOW_VOLT": 10})
    assert fallback.vehicle is ROVER and "assumed" in fallback.how
    assert "assumed" in detect_vehicle({"RTL_ALT": 1500, "CRUISE_SPEED": 2}).how  # two vehicles: no guess
    assert detect_vehicle({"SURFACE_DEPTH": -10}, "copter").vehicle is COPTER


# -- items 2 and 3: CRITICAL timed like LOW, strictly greater; LOW_TIMER = 0 disables


@pytest.mark.parametrize("level", ["LOW", "CRT"])
def test_voltage_timer_is_strictly_greater(level: str) -> None:
    """AP_BattMonitor_Backend.cpp update_failsafes: `now - start_ms > _low_voltage_timeout*1000U`,
    for critical_voltage_start_ms exactly as for low_voltage_start_ms."""
    fs = fs_for({f"BATT_{level}_VOLT": 10.5, "BATT_LOW_TIMER": 10})
    assert feed(fs, [(5.0, 10.4), (15.0, 10.4)]) == []  # exactly 10 s: not yet
    [event] = feed(fs, [(15.001, 10.4)])
    assert event.time == 15.001 and event.level is (Level.LOW if level == "LOW" else Level.CRITICAL)


def test_recovery_restarts_the_timer() -> None:
    """update_failsafes: 'acceptable voltage so reset timer' (start_ms = 0)."""
    fs = fs_for({"BATT_CRT_VOLT": 10.0})
    assert feed(fs, [*steps(0, 9.9, 9.9), (10.0, 10.2), *steps(10.1, 20.1, 9.9)]) == []
    assert feed(fs, [(20.2, 9.9)])[0].level is Level.CRITICAL


def test_low_timer_zero_disables_voltage_failsafes() -> None:
    """AP_BattMonitor_Params.cpp LOW_TIMER: "A value of zero disables low voltage errors";
    update_failsafes checks `_low_voltage_timeout > 0`. Capacity still triggers."""
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10.0, "BATT_LOW_TIMER": 0, "BATT_CRT_MAH": 500})
    assert feed(fs, steps(0, 600, 9.0, 1.0)) == []
    events = fs.update(601, BatteryReading(voltage_v=9.0, consumed_mah=2900), armed=True)
    assert [(e.level, e.cause) for e in events] == [(Level.CRITICAL, "capacity")]


def test_seed_critical_variant_triggers_at_once_and_overrides() -> None:
    """Seed AN-00035 FR-DRAFT-2 ("Trigger immediately ... (no hysteresis)", "CRITICAL overrides LOW
    action"), opt-in; ArduPilot (update_failsafes) would wait BATT_LOW_TIMER and apply the priority."""
    values = {"BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10.0, "BATT_FS_LOW_ACT": 2, "BATT_FS_CRT_ACT": 1}
    ap = fs_for(values)
    low = feed(ap, steps(0, 10.1, 10.4))
    assert [e.level for e in low] == [Level.LOW]
    crit = feed(ap, steps(10.2, 20.3, 9.5))
    assert [e.time for e in crit] == [20.3] and not crit[0].executed  # RTL (index 2) after Hold (index 1)
    seed = fs_for(values, variants=["seed-critical"])
    feed(seed, steps(0, 10.1, 10.4))
    [e] = feed(seed, [(10.2, 9.5)])
    assert (e.time, e.level, e.executed, e.outcome) == (10.2, Level.CRITICAL, True, "rtl")


# -- item 4: BATT_FS_VOLTSRC = 1, the resting voltage


def test_resting_voltage_estimate_restated() -> None:
    """AP_BattMonitor_Backend.cpp update_resistance_estimate / voltage_resting_estimate, TC_1 0.5,
    TC_2 0.1 (AP_BattMonitor.h): a 12.6 V pack sagging 0.05 V per extra ampere."""
    est = ResistanceEstimator()
    t = 0
    for amps in [1.0, 5.0, 10.0, 20.0, 20.0, 5.0, 30.0] * 20:
        t += 100
        est.update(t, 12.6 - 0.05 * amps, amps)
    assert 0.0 < est.resistance <= 0.05 + 1e-9  # capped by the largest drop from the highest voltage
    assert est.resting(11.1) == pytest.approx(max(11.1, est.resting_voltage))
    assert est.resting(20.0) == 20.0  # never below the raw voltage
    before = est.resistance
    est.update(t + 100, 12.0, None)  # no current: nothing learned
    est.update(t + 200, 12.0, 0.0)
    assert est.resistance == before


def test_sag_compensated_source_rides_out_load_sag() -> None:
    """check_failsafe_types: voltage_used = voltage_resting_estimate() when FS_VOLTSRC = 1."""
    rows = []
    for i in range(1200):  # 120 s at 10 Hz of 2 s pulses of 2 A / 14 A, 0.05 ohm; the resting voltage is
        amps = 14.0 if (i // 20) % 2 else 2.0  # 12.0 V for a minute, then 10.8 V: loaded, ~10.1 V
        rows.append((i / 10, (12.0 if i < 600 else 10.8) - 0.05 * amps, amps))

    def run(src: int) -> list[Event]:
        fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_FS_VOLTSRC": src, "BATT_LOW_TIMER": 1})
        out: list[Event] = []
        for t, v, a in rows:
            out += fs.update(t, BatteryReading(voltage_v=v, current_a=a), armed=True)
        return out

    raw = run(0)
    assert [(e.level, e.voltage_source) for e in raw] == [(Level.LOW, "raw")]
    assert run(1) == []


# -- item 5: the priority rule across all batteries


def test_priority_rule_across_two_batteries() -> None:
    """AP_BattMonitor.cpp check_failsafes: `if (priority <= _highest_failsafe_priority)` run the
    handler; _highest_failsafe_priority is one for all instances (INT8_MAX at init)."""
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 2, "BATT2_LOW_VOLT": 10.5, "BATT2_FS_LOW_ACT": 1})
    first = feed(fs, steps(0, 11, 10.4, 1.0), instance=1)  # battery 1: Hold (index 1) runs
    second = feed(fs, steps(20, 31, 10.4, 1.0), instance=2)  # battery 2: RTL (index 2) may not
    assert [(e.battery, e.action, e.executed, e.outcome) for e in first + second] == [
        (1, "Hold", True, "hold"),
        (2, "RTL", False, "not run"),
    ]
    assert second[0].ardupilot_text == "Battery 2 is low 10.40V used 0 mAh"  # still announced
    same = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 2, "BATT2_LOW_VOLT": 10.5, "BATT2_FS_LOW_ACT": 2})
    feed(same, steps(0, 11, 10.4, 1.0), instance=1)
    assert feed(same, steps(20, 31, 10.4, 1.0), instance=2)[0].executed  # "valid to retrigger the same action"


def test_levels_only_rise_and_survive_recovery_and_disarming() -> None:
    """check_failsafes: `if (type <= state[i].failsafe) continue`; only reset_remaining clears it;
    nothing is checked while disarmed (`if (hal.util->get_soft_armed())`)."""
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10.0, "BATT_FS_CRT_ACT": 2})
    assert [e.level for e in feed(fs, steps(0, 11, 10.4, 1.0))] == [Level.LOW]
    assert feed(fs, steps(12, 30, 12.0, 1.0)) == []  # recovered: LOW stays
    assert fs.update(31, BatteryReading(voltage_v=9.0), armed=False) == []
    assert fs.level is Level.LOW
    crit = feed(fs, steps(32, 43, 9.0, 1.0))
    assert [e.level for e in crit] == [Level.CRITICAL] and crit[0].executed  # Hold (1) <= INT8_MAX


# -- items 6 and 7: no distance trigger; capacity = CAPACITY - consumed, only with current


def test_no_distance_trigger_by_default() -> None:
    """AP_BattMonitor_Backend.cpp check_failsafe_types knows voltage and capacity only; the seed's
    Phase 2 distance rule (FR-DRAFT-5) is the opt-in variant "distance"."""
    rows = [(float(t), BatteryReading(voltage_v=11.5, current_a=20.0)) for t in range(0, 600)]
    plain = fs_for({})
    assert not [e for t, r in rows for e in plain.update(t, r, armed=True, distance_to_home_m=t * 5.0)]
    variant = fs_for({}, variants=["distance"])
    events = [e for t, r in rows for e in variant.update(t, r, armed=True, distance_to_home_m=t * 5.0)]
    assert [(e.level, e.cause) for e in events] == [(Level.LOW, "distance")]
    assert events[0].text.endswith("needed to return")


def test_capacity_is_capacity_minus_consumed_and_needs_current() -> None:
    """check_failsafe_types: `has_current() && (_pack_capacity - consumed_mah) < _low_capacity`."""
    fs = fs_for({"BATT_CAPACITY": 3000, "BATT_LOW_MAH": 600})
    assert fs.update(0, BatteryReading(voltage_v=11.0, consumed_mah=2400), armed=True) == []  # 600: not below
    [e] = fs.update(1, BatteryReading(voltage_v=11.0, consumed_mah=2401), armed=True)
    assert (e.cause, e.value, e.threshold) == ("capacity", 599, 600)
    assert e.ardupilot_text == "Battery 1 is low 11.00V used 2401 mAh"
    volts_only = fs_for({"BATT_CAPACITY": 3000, "BATT_LOW_MAH": 600, "BATT_MONITOR": 3})  # Analog Voltage Only
    assert volts_only.update(0, BatteryReading(voltage_v=11.0, consumed_mah=2900), armed=True) == []


def test_consumed_charge_integrates_current_like_the_analog_backend() -> None:
    """AP_BattMonitor_Analog::read: consumed_mah += current * dt, gaps of 2 s or more skipped."""
    fs = fs_for({"BATT_CAPACITY": 1000, "BATT_CRT_MAH": 500})
    events: list[Event] = []
    for i in range(0, 1201):  # 60 A for 30 s at 40 Hz: 500 mAh, then below
        events += fs.update(i / 40, BatteryReading(voltage_v=11.0, current_a=60.0), armed=True)
    assert [(e.time, e.cause) for e in events] == [(30.0, "capacity")]
    assert fs.monitors[1].consumed_mah == pytest.approx(500, abs=0.01)
    fs.update(40.0, BatteryReading(voltage_v=11.0, current_a=60.0), armed=True)  # a 10 s gap: skipped
    assert fs.monitors[1].consumed_mah == pytest.approx(500, abs=0.01)


# -- item 8: ranges and defaults


def test_ardupilot_defaults_and_ranges() -> None:
    """AP_BattMonitor_Params.cpp: DEFAULT_LOW_BATTERY_VOLTAGE 10.5 on Copter, else 0; CAPACITY 3300;
    LOW_TIMER 10 with @Range 0 120; no range on the voltages (a 12S pack is fine)."""
    assert battery_settings({}, COPTER)[1].low_volt == 10.5
    assert battery_settings({}, ROVER)[1] == BatterySettings(1)
    assert (BatterySettings(1).capacity_mah, BatterySettings(1).low_timer_s) == (3300, 10)
    twelve_s = {"BATT_LOW_VOLT": 42.0, "BATT_CRT_VOLT": 40.8}
    assert check_settings(twelve_s) == []
    from generated.params import BattParams

    assert BattParams(BATT_LOW_VOLT=50.4).validate() == []
    assert [str(v.path) for v in BattParams(BATT_LOW_TIMER=121).validate()] == ["BATT_LOW_TIMER"]
    codes = {f.param: f.severity for f in check_settings({"BATT_FS_LOW_ACT": 6, "BATT_FS_CRT_ACT": 6})}
    assert codes == {"BATT_FS_LOW_ACT": "error", "BATT_FS_CRT_ACT": "error"}  # rover has no 6
    assert check_settings({"BATT_FS_LOW_ACT": 6}, vehicle=COPTER) == []
    assert [f.param for f in check_settings({"BATT_FS_LOW_ACT": 5}, vehicle=PLANE)] == ["BATT_FS_LOW_ACT"]
    assert check_settings({"BATT_FS_CRT_ACT": 5}, vehicle=PLANE) == []  # Parachute: CRITICAL only


# -- item 9: every battery instance


def test_every_instance_prefix() -> None:
    """AP_BattMonitor.cpp var_info: "_", "2_" .. "9_", "A_" .. "G_" (instances 1..16)."""
    assert [prefix(i) for i in range(1, 17)] == [
        "BATT_",
        *(f"BATT{n}_" for n in range(2, 10)),
        *(f"BATT{c}_" for c in "ABCDEFG"),
    ]
    assert split_name("BATTG_LOW_VOLT") == (16, "LOW_VOLT") and split_name("BATTX_LOW_VOLT") is None
    settings = battery_settings({"BATTA_LOW_VOLT": 22.0, "BATTA_FS_LOW_ACT": 5, "BATT2_MONITOR": 0}, ROVER)
    assert sorted(settings) == [1, 2, 10] and settings[10].low_volt == 22.0 and not settings[2].enabled
    fs = make_failsafe(settings, ROVER)
    [e] = feed(fs, steps(0, 11, 21.0, 1.0), instance=10)
    assert (e.battery, e.action, e.outcome) == (10, "Terminate", "disarm")
    assert feed(fs, steps(20, 60, 1.0, 1.0), instance=2) == []  # BATT2_MONITOR = 0: no monitor


def test_levels_map_onto_uorb_warning_and_mavlink_charge_state() -> None:
    """AP_BattMonitor.cpp get_mavlink_charge_state: Low -> LOW, Critical -> CRITICAL."""
    mavlink = importlib.import_module("generated.mavlink")
    fs = fs_for({"BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10.0})
    low = feed(fs, steps(0, 11, 10.4, 1.0))[0]
    crit = feed(fs, steps(12, 23, 9.0, 1.0))[0]
    assert low.mavlink_charge_state == mavlink.MavBatteryChargeState.LOW
    assert crit.mavlink_charge_state == mavlink.MavBatteryChargeState.CRITICAL
    assert low.uorb_warning < crit.uorb_warning
    assert apply_level("mavlink.BATTERY_STATUS", {}, Level.NONE) == {"charge_state": mavlink.MavBatteryChargeState.OK}


def test_the_levels_written_out_are_the_generated_enums() -> None:
    """levels.py writes the enums' values out (importing the generated messages costs a replay's start-up)."""
    mavlink, uorb = importlib.import_module("generated.mavlink"), importlib.import_module("generated.uorb")
    warning, state = uorb.BatteryStatusWarning, mavlink.MavBatteryChargeState
    assert UORB_WARNING == {level: int(warning[level.name]) for level in Level}
    assert MAVLINK_CHARGE_STATE == {Level.NONE: state.OK, Level.LOW: state.LOW, Level.CRITICAL: state.CRITICAL}


def test_time_must_not_go_back() -> None:
    fs = fs_for({})
    fs.update(5, BatteryReading(voltage_v=11.0), armed=True)
    with pytest.raises(ValueError, match="never go back"):
        fs.update(4, BatteryReading(voltage_v=11.0), armed=True)
