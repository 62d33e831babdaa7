"""The px4 policy, rule by rule, against independent references.

Arithmetic is recomputed with numpy's float32 / float16 / integer types (a second implementation
of what PX4's C code does, independent of the generated runtime helpers), and the MAVLink bytes
the stream would send are packed by pymavlink and compared with our codec's payload. Each test
names the PX4 source line it pins.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import common as v20

from generated.convert import LossReport
from generated.convert.dronecan_mavlink import dronecan_to_mavlink, mavlink_to_dronecan
from generated.convert.dronecan_uorb import dronecan_to_uorb, uorb_to_dronecan
from generated.convert.uorb_mavlink import mavlink_to_uorb, uorb_to_mavlink
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo, BatteryInfoStatusFlag
from generated.mavlink import BatteryStatus as MavBatteryStatus
from generated.uorb import BatteryStatus, BatteryStatusState, BatteryStatusWarning

F32, F16 = np.float32, np.float16


def c_int(x: np.float32, dtype: type) -> int:
    """float -> integer as a Cortex-M stores it: truncate, saturate to 32 bits, keep the low bits."""
    if math.isnan(float(x)):
        return 0
    info = np.iinfo(dtype)
    wide = (
        np.int64(max(-(2**31), min(2**31 - 1, math.trunc(float(x)))))
        if info.min < 0
        else np.int64(max(0, min(2**32 - 1, math.trunc(float(x)))))
    )
    return int(wide.astype(dtype))


# -- the fixed cases ---------------------------------------------------------------


def test_298_15_kelvin_arrives_as_298_25_and_leaves_as_2510_cdegc() -> None:
    assert float(F16(298.15)) == 298.25
    status = dronecan_to_uorb(BatteryInfo(temperature=298.15), policy="px4")
    expected = F32(F32(F16(298.15)) + F32(-273.15))  # msg.temperature + kAbsoluteNullCelsius
    assert status.temperature == float(expected)
    mav = uorb_to_mavlink(status, policy="px4")
    assert mav.temperature == 2510 == c_int(F32(expected * F32(100.0)), np.int16)


def test_soc_127_is_1_27_under_px4_and_unknown_under_strict() -> None:
    px4 = dronecan_to_uorb(BatteryInfo(state_of_charge_pct=127), policy="px4")
    assert px4.remaining == float(F32(127) / F32(100.0)) == pytest.approx(1.27)
    assert dronecan_to_uorb(BatteryInfo(state_of_charge_pct=127)).remaining == -1.0
    assert uorb_to_mavlink(px4, policy="px4").battery_remaining == 127  # roundf(1.27f * 100.f)


def test_battery_id_0_becomes_mavlink_id_255() -> None:
    status = dronecan_to_uorb(BatteryInfo(battery_id=0), policy="px4")
    assert status.id == 0  # id = msg.battery_id
    assert uorb_to_mavlink(status, policy="px4").id == 255  # bat_msg.id = battery_status.id - 1 (uint8)
    assert dronecan_to_mavlink(BatteryInfo(battery_id=0), policy="px4").id == 255
    assert dronecan_to_mavlink(BatteryInfo(battery_id=0)).id == 0  # strict keeps the index


# -- uavcan battery bridge (src/drivers/uavcan/sensors/battery.cpp) ------------------------------


def test_bridge_raw_mode_fields() -> None:
    info = BatteryInfo(voltage=16.8, current=12.5, status_flags=BatteryInfoStatusFlag.IN_USE | 8,
                       full_charge_capacity_wh=99.0, remaining_capacity_wh=44.0, state_of_charge_pct=44)  # fmt: skip
    s = dronecan_to_uorb(info, policy="px4")
    assert s.voltage_v == float(F16(16.8)) and s.current_a == 12.5 and s.connected
    assert s.source == 1 and s.faults == 0  # source = status_flags & IN_USE; faults not filled
    assert s.scale == -1.0 and math.isnan(s.time_remaining_s)
    assert s.cell_count == 1 and s.voltage_cell_v[0] == float(F16(16.8))  # "hack" for MAVLink
    assert s.full_charge_capacity_wh == 99.0 and s.remaining_capacity_wh == 44.0
    assert s.current_average_a == 0.0 and s.discharged_mah == 0.0  # state PX4 carries between messages: zero start
    assert dronecan_to_uorb(BatteryInfo(status_flags=8), policy="px4").source == 0


@pytest.mark.parametrize(
    ("pct", "warning"),
    [(4, BatteryStatusWarning.EMERGENCY), (5, BatteryStatusWarning.CRITICAL), (6, BatteryStatusWarning.CRITICAL),
     (7, BatteryStatusWarning.LOW), (14, BatteryStatusWarning.LOW), (15, BatteryStatusWarning.NONE),
     (127, BatteryStatusWarning.NONE)],
)  # fmt: skip
def test_bridge_warning_thresholds(pct: int, warning: int) -> None:
    # determineWarning(remaining): < BAT_EMERGEN_THR 0.05, < BAT_CRIT_THR 0.07, < BAT_LOW_THR 0.15 (float32)
    remaining = F32(pct) / F32(100.0)
    expected = 3 if remaining < F32(0.05) else 2 if remaining < F32(0.07) else 1 if remaining < F32(0.15) else 0
    assert expected == warning
    assert dronecan_to_uorb(BatteryInfo(state_of_charge_pct=pct), policy="px4").warning == warning


def test_bridge_aux_fields() -> None:
    info = BatteryInfo(voltage=12.0, full_charge_capacity_wh=50.0)
    aux = BatteryInfoAux(voltage_cell=[4.0, 4.1, 3.9], cycle_count=12, over_discharge_count=1,
                         nominal_voltage=11.1, is_powering_off=True)  # fmt: skip
    s = dronecan_to_uorb(info, aux, policy="px4")
    assert s.cell_count == 3 and s.voltage_cell_v[:3] == [float(F16(v)) for v in (4.0, 4.1, 3.9)]
    assert (s.cycle_count, s.over_discharge_count, s.is_powering_off) == (12, 1, True)
    assert s.nominal_voltage == float(F16(11.1))
    # capacity = full_charge_capacity_wh * 1000.f / nominal_voltage, stored as uint16
    assert s.capacity == c_int(F32(F32(F32(50.0) * F32(1000.0)) / F32(F16(11.1))), np.uint16)
    no_nominal = dronecan_to_uorb(info, BatteryInfoAux(nominal_voltage=0.0), policy="px4")
    assert math.isnan(no_nominal.nominal_voltage) and no_nominal.capacity == 0 and no_nominal.cell_count == 0


# -- MAVLink stream (src/modules/mavlink/streams/BATTERY_STATUS.hpp) -----------------------------


def _pymavlink_payload(m: MavBatteryStatus) -> bytes:
    msg = v20.MAVLink_battery_status_message(
        m.id, m.battery_function, m.type, m.temperature, m.voltages, m.current_battery, m.current_consumed,
        m.energy_consumed, m.battery_remaining, m.time_remaining, m.charge_state, m.voltages_ext, m.mode,
        m.fault_bitmask,
    )  # fmt: skip
    mav = v20.MAVLink(None)
    frame = msg.pack(mav)
    return bytes(frame[10 : 10 + frame[1]])  # MAVLink 2 header is 10 bytes; frame[1] is the payload length


@settings(max_examples=150, deadline=None)
@given(
    connected=st.booleans(),
    voltage=st.floats(0, 200, width=32),
    current=st.floats(-400, 400, width=32),
    remaining=st.floats(-1, 1.25, width=32),
    temperature=st.one_of(st.just(math.nan), st.floats(-60, 120, width=32)),
    time_remaining=st.one_of(st.just(math.nan), st.floats(0, 1e6, width=32)),
    discharged=st.floats(-1, 1e6, width=32),
    cells=st.lists(st.floats(0, 5, width=32), max_size=14),
    warning=st.sampled_from([0, 1, 2, 3, 4, 5, 6, 7]),
    battery_id=st.integers(0, 255),
    faults=st.integers(0, 0x7FF),
)
def test_stream_matches_a_float32_model_and_pymavlink_bytes(
    connected: bool, voltage: float, current: float, remaining: float, temperature: float, time_remaining: float,
    discharged: float, cells: list[float], warning: int, battery_id: int, faults: int,
) -> None:  # fmt: skip
    s = BatteryStatus(connected=connected, voltage_v=voltage, current_a=current, remaining=remaining,
                      temperature=temperature, time_remaining_s=time_remaining, discharged_mah=discharged,
                      cell_count=len(cells), voltage_cell_v=cells + [0.0] * (14 - len(cells)), warning=warning,
                      id=battery_id, faults=faults)  # fmt: skip
    m = uorb_to_mavlink(s, policy="px4")
    assert m.id == (battery_id - 1) % 256 and (m.battery_function, m.type, m.energy_consumed, m.mode) == (1, 1, -1, 0)
    assert m.current_consumed == (c_int(F32(discharged), np.int32) if connected else -1)
    assert m.current_battery == (c_int(F32(current) * F32(100.0), np.int16) if connected else -1)
    # PX4 uses C roundf (halves away from zero); numpy's round takes halves to even
    percent = F32(remaining) * F32(100.0)
    rounded = np.copysign(np.floor(np.abs(percent) + F32(0.5)), percent)
    assert m.battery_remaining == (c_int(rounded, np.int8) if connected else -1)
    finite_t = connected and math.isfinite(time_remaining)
    assert m.time_remaining == (max(c_int(F32(time_remaining), np.int32), 1) if finite_t else 0)
    assert m.charge_state == {0: 1, 1: 2, 2: 3, 3: 4, 4: 5, 6: 6, 7: 7}.get(warning, 0)
    assert m.fault_bitmask == faults
    finite = connected and math.isfinite(temperature)
    assert m.temperature == (c_int(F32(temperature) * F32(100.0), np.int16) if finite else 32767)
    main, ext = [65535] * 10, [0] * 4
    if connected:
        if not cells or F32(cells[0]) < F32(0.0001):
            total = F32(voltage) * F32(1000.0)
            n = c_int(total, np.int32) // 65534 + 1
            if n <= 10:
                rest = total
                for i in range(n - 1):
                    main[i] = 65534
                    rest = F32(rest - F32(65534))
                main[n - 1] = c_int(rest, np.uint16)
        else:
            for i, c in enumerate(cells):
                v = c_int(F32(c) * F32(1000.0), np.uint16)
                if i < 10:
                    main[i] = v
                else:
                    ext[i - 10] = v
    assert (m.voltages, m.voltages_ext) == (main, ext)
    if hasattr(m, "encode"):
        assert m.encode() == _pymavlink_payload(m)  # both MAVLink 2 payloads, trailing zeros truncated


def test_stream_centiamp_overflow_wraps_as_on_the_vehicle() -> None:
    report = LossReport()
    m = uorb_to_mavlink(BatteryStatus(connected=True, current_a=400.0), policy="px4", report=report)
    assert m.current_battery == c_int(F32(40000.0), np.int16) == -25536  # int16 keeps the low 16 bits
    assert ("clamped", "mavlink.BATTERY_STATUS.current_battery") in {(e.kind, e.field) for e in report}
    strict = uorb_to_mavlink(BatteryStatus(connected=True, current_a=400.0))
    assert strict.current_battery == 32767


# -- MAVLink receiver (src/modules/mavlink/mavlink_receiver.cpp) -----------------------------------


def test_receiver_fields() -> None:
    m = MavBatteryStatus(voltages=[4100, 4050, 4000] + [65535] * 7, current_battery=1234, battery_remaining=-1,
                         current_consumed=321, temperature=2510, voltages_ext=[3900, 0, 0, 0])  # fmt: skip
    s = mavlink_to_uorb(m, policy="px4")
    cells = [F32(F32(v) / F32(1000.0)) for v in (4100, 4050, 4000)]
    assert s.voltage_cell_v[:3] == [float(c) for c in cells] and s.cell_count == 3
    assert s.voltage_v == float(F32(F32(cells[0] + cells[1]) + cells[2]))
    assert s.current_a == float(F32(1234) / F32(100.0)) and s.remaining == float(F32(-1) / F32(100.0))
    assert s.discharged_mah == 321.0 and s.temperature == 2510.0 and s.connected
    assert s.warning == BatteryStatusWarning.EMERGENCY  # remaining -0.01 < 0.05
    assert s.id == 0 and s.time_remaining_s == 0.0 and s.scale == 0.0  # battery_status_s{} zero-initialised


# -- uavcannode publisher (src/drivers/uavcannode/Publishers/BatteryInfo.hpp) ----------------------


def test_uavcannode_publisher_fields() -> None:
    s = BatteryStatus(connected=True, voltage_v=16.2, current_a=-3.0, temperature=25.1, remaining=0.876,
                      max_error=300, state_of_health=95, id=2, warning=BatteryStatusState.CHARGING, cell_count=2,
                      voltage_cell_v=[4.05, 4.06] + [0.0] * 12, nominal_voltage=14.8, cycle_count=7)  # fmt: skip
    info, aux = uorb_to_dronecan(s, policy="px4")
    assert info.voltage == float(F16(F32(16.2))) and info.current == -3.0
    assert info.temperature == float(F16(F32(F32(25.1) + F32(273.15))))
    assert info.state_of_charge_pct == min(c_int(F32(0.876) * F32(100.0), np.uint8), 127) == 87
    assert info.state_of_charge_pct_stdev == min(300 % 256, 127)  # uint8 store, then uint7 saturation
    assert (info.battery_id, info.state_of_health_pct, info.model_instance_id) == (2, 95, 0)
    assert info.model_name == b"PX4 CAN Battery"
    assert info.status_flags == BatteryInfoStatusFlag.IN_USE | BatteryInfoStatusFlag.CHARGING
    assert aux.voltage_cell == [float(F16(F32(4.05))), float(F16(F32(4.06)))]
    assert (aux.cycle_count, aux.battery_id, aux.max_current) == (7, 2, -3.0)


def test_px4_chains_through_battery_status_like_a_vehicle() -> None:
    info = BatteryInfo(voltage=12.6, state_of_charge_pct=50, battery_id=1, temperature=300.0)
    assert dronecan_to_mavlink(info, policy="px4") == uorb_to_mavlink(
        dronecan_to_uorb(info, policy="px4"), policy="px4"
    )
    m = MavBatteryStatus(voltages=[12600] + [65535] * 9, battery_remaining=50)
    assert mavlink_to_dronecan(m, policy="px4") == uorb_to_dronecan(mavlink_to_uorb(m, policy="px4"), policy="px4")


@pytest.mark.parametrize(("remaining", "percent"), [(0.125, 13), (0.005, 1), (0.995, 100), (0.0, 0)])
def test_remaining_rounds_halves_away_from_zero_as_roundf(remaining: float, percent: int) -> None:
    # battery_remaining = roundf(remaining * 100.f): 12.5 -> 13, where round-half-even would give 12
    status = BatteryStatus(connected=True, remaining=remaining)
    assert uorb_to_mavlink(status, policy="px4").battery_remaining == percent
