"""Converters of MAVLink BATTERY_INFO (common.xml) and BATTERY_STATUS_V2 (development.xml): their
invalid markers read as unknown and are written back, units convert (Ah, g, cdegC, %), status
flags split into charging, warning and faults, and round trips keep every mapped field."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from generated.convert import CONVERTERS, LossReport
from generated.convert.mavlink_info import from_concepts as info_from_concepts
from generated.convert.mavlink_info import to_concepts as info_to_concepts
from generated.convert.mavlink_v2 import from_concepts as v2_from_concepts
from generated.convert.mavlink_v2 import to_concepts as v2_to_concepts
from generated.convert.uorb_mavlink_v2 import mavlink_v2_to_uorb, uorb_to_mavlink_v2
from generated.mavlink import BatteryInfo, BatteryStatusV2, MavBatteryStatusFlags
from generated.uorb import BatteryStatus

F = MavBatteryStatusFlags


def test_every_marker_of_battery_info_reads_unknown_and_is_written_back() -> None:
    state = info_to_concepts(BatteryInfo(id=2))
    known = {k: v for k, v in state.to_dict().items() if v is not None}
    assert known == {"battery_index": 2, "connected": True}
    report = LossReport()
    back = info_from_concepts(state, report=report)
    assert back == BatteryInfo(id=2)  # UINT8_MAX, UINT16_MAX, 0, NaN and empty texts again
    assert math.isnan(back.full_charge_capacity) and (back.state_of_health, back.cycle_count) == (255, 65535)
    assert "mavlink.BATTERY_INFO.serial_number" in report.fields("unknown")
    assert not back.is_known("serial_number") and BatteryInfo(serial_number="X1").is_known("serial_number")


def test_battery_info_values_in_si() -> None:
    info = BatteryInfo(
        id=1, battery_function=2, type=1, state_of_health=87, cells_in_series=6, cycle_count=120, weight=1450,
        discharge_minimum_voltage=3.25, charging_maximum_voltage=4.25, nominal_voltage=22.5, design_capacity=5.0,
        full_charge_capacity=4.5, discharge_maximum_current=60.0, manufacture_date="01022025",
        serial_number="SN-0042", name="ACME_Pack6S",
    )  # fmt: skip
    s = info_to_concepts(info)
    assert (s.battery_function, s.chemistry, s.cell_count, s.cycle_count) == ("propulsion", "lipo", 6, 120)
    assert s.state_of_health == 0.87 and s.weight == 1.45 and s.design_capacity == 18000.0
    assert s.full_capacity == 4.5 * 3600 and s.max_discharge_current == 60.0 and s.nominal_voltage == 22.5
    assert (s.serial_number_text, s.manufacture_date, s.model_name) == ("SN-0042", "01022025", "ACME_Pack6S")
    assert s.cell_discharge_min_voltage == 3.25 and s.cell_rest_min_voltage is None
    assert info_from_concepts(s) == info


def test_battery_status_v2_flags_units_and_markers() -> None:
    flags = F.CHARGING | F.FAULT_OVER_TEMPERATURE
    flags |= F.CELL_BALANCING
    report = LossReport()
    s = v2_to_concepts(
        BatteryStatusV2(id=0, temperature=2510, voltage=24.0, current=-3.5, capacity_consumed=1.25,
                        capacity_remaining=2.0, state_of_charge=61.0, status_flags=flags),
        report=report,
    )  # fmt: skip
    assert s.charging is True and s.warning == "charging" and s.faults == ("over_temperature",)
    assert s.discharged == 4500.0 and s.remaining_capacity == 7200.0 and s.state_of_charge == 0.61
    assert math.isclose(s.temperature or 0, 298.25) and (s.pack_voltage, s.current) == (24.0, -3.5)
    assert [e.to_dict()["detail"] for e in report.entries if e.kind == "dropped"] == ["bits 0x4 have no counterpart"]
    unknown = v2_to_concepts(BatteryStatusV2())  # INT16_MAX and NaN everywhere
    assert (unknown.temperature, unknown.pack_voltage, unknown.state_of_charge, unknown.discharged) == (None,) * 4
    back = v2_from_concepts(unknown)
    assert back.temperature == 32767 and math.isnan(back.voltage) and math.isnan(back.state_of_charge)


def test_state_of_charge_above_100_percent_is_unknown() -> None:
    assert v2_to_concepts(BatteryStatusV2(state_of_charge=120.0)).state_of_charge is None


@settings(max_examples=60, derandomize=True, deadline=None)
@given(
    st.integers(0, 255),
    st.integers(-27315, 32766),
    st.floats(0, 100, width=32),
    st.floats(-500, 500, width=32),
    st.floats(0, 100, width=32),
)
def test_battery_status_v2_round_trip(battery: int, centi_c: int, volts: float, amps: float, soc: float) -> None:
    msg = BatteryStatusV2(id=battery, temperature=centi_c, voltage=volts, current=amps, state_of_charge=soc,
                          status_flags=F.FAULT_OVER_CURRENT)  # fmt: skip
    back = v2_from_concepts(v2_to_concepts(msg))
    assert (back.id, back.temperature, back.voltage, back.current, back.status_flags) == (
        msg.id, msg.temperature, msg.voltage, msg.current, msg.status_flags,
    )  # fmt: skip
    assert math.isclose(back.state_of_charge, soc, rel_tol=1e-6, abs_tol=1e-5)


def test_px4_battery_status_to_and_from_battery_status_v2() -> None:
    assert ("uorb", "mavlink_v2") in CONVERTERS and ("mavlink_info", "mavlink") in CONVERTERS
    px4 = BatteryStatus(id=1, connected=True, voltage_v=16.5, current_a=12.0, discharged_mah=850.0, remaining=0.42,
                        temperature=31.5, max_error=1)  # fmt: skip
    v2 = uorb_to_mavlink_v2(px4)
    assert (v2.id, v2.voltage, v2.current, v2.temperature) == (0, px4.voltage_v, px4.current_a, 3150)
    assert math.isclose(v2.capacity_consumed, 0.85, rel_tol=1e-6) and math.isclose(v2.state_of_charge, 42.0)
    again = mavlink_v2_to_uorb(v2)
    assert (again.id, again.voltage_v, again.current_a, again.temperature) == (1, 16.5, 12.0, 31.5)
    assert math.isclose(again.discharged_mah, 850.0, rel_tol=1e-6) and math.isclose(again.remaining, 0.42, rel_tol=1e-6)
