"""The ardupilot policy (DroneCAN BatteryInfo -> MAVLink BATTERY_STATUS as ArduPilot sends it), rule by rule.

Each test names the ArduPilot function it pins (libraries/AP_BattMonitor/AP_BattMonitor_DroneCAN.cpp,
AP_BattMonitor_Backend.cpp, AP_BattMonitor.cpp, libraries/AP_Math/AP_Math.cpp and GCS_Common.cpp's
send_battery_status) and recomputes the firmware's arithmetic with numpy's float32 / float16 types, a second
implementation independent of the generated runtime. The BATTERY_STATUS each conversion gives is packed by
pymavlink and compared with our codec's payload, so every value is one ArduPilot could send.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import ardupilotmega as mav

from generated.convert import POLICIES, ConversionError, LossReport
from generated.convert.dronecan_mavlink import dronecan_to_mavlink
from generated.convert.dronecan_uorb import dronecan_to_uorb
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo
from generated.mavlink import BatteryStatus

F32, F16 = np.float32, np.float16
AUS_TO_MAH = F32(0.0000002778)  # AP_Math/definitions.h


def ap(info: BatteryInfo, aux: BatteryInfoAux | None = None, **inputs: float) -> BatteryStatus:
    out = dronecan_to_mavlink(info, aux, policy="ardupilot", **inputs)
    assert isinstance(out, BatteryStatus)
    return out


def c_int(x: float, bits: int, signed: bool) -> int:
    """A float stored in a C integer on a Cortex-M: truncate, saturate to 32 bits (NaN 0), keep the low bits."""
    if math.isnan(x):
        return 0
    lo, hi = (-(2**31), 2**31 - 1) if signed else (0, 2**32 - 1)
    wide = max(lo, min(hi, math.trunc(x)))
    low = wide & ((1 << bits) - 1)
    return low - (1 << bits) if signed and low >= 1 << (bits - 1) else low


def pymavlink_payload(msg: BatteryStatus) -> bytes:
    m = mav.MAVLink_battery_status_message(
        msg.id, msg.battery_function, msg.type, msg.temperature, msg.voltages, msg.current_battery,
        msg.current_consumed, msg.energy_consumed, msg.battery_remaining, msg.time_remaining, msg.charge_state,
        msg.voltages_ext, msg.mode, msg.fault_bitmask,
    )  # fmt: skip
    packer = mav.MAVLink(None, srcSystem=1, srcComponent=1)
    return bytes(m.pack(packer)[10:-2])


# -- the policy exists where ArduPilot has the code path ------------------------------------------------


def test_ardupilot_policy_is_dronecan_to_mavlink_only() -> None:
    assert POLICIES[("dronecan", "mavlink")] == ("strict", "px4", "ardupilot")
    assert "ardupilot" not in POLICIES[("uorb_v0", "uorb")]  # ArduPilot has no uORB
    with pytest.raises(ConversionError, match="no ardupilot behaviour converts dronecan to uorb"):
        dronecan_to_uorb(BatteryInfo(), policy="ardupilot")


# -- update_interim_state / send_battery_status: temperature ------------------------------------------


def test_temperature_is_kelvin_minus_273_15f_in_centidegrees_truncated() -> None:
    k = F32(F16(298.15))  # 298.25 as float16 carries it
    expected = c_int(float(F32(F32(k - F32(273.15)) * F32(100))), 16, True)  # (int16_t)(temp * 100)
    assert ap(BatteryInfo(temperature=298.15)).temperature == expected == 2510
    k = F32(F16(250.0))  # below 0 degC: truncation goes toward zero
    assert ap(BatteryInfo(temperature=250.0)).temperature == c_int(float(F32(F32(k - F32(273.15)) * 100)), 16, True)


@pytest.mark.parametrize("kelvin", [math.nan, 0.0, -5.0])
def test_temperature_not_a_number_above_zero_is_int16_max(kelvin: float) -> None:
    # update_interim_state: if (!isnan(temperature_K) && temperature_K > 0) ... else no temperature_time
    assert ap(BatteryInfo(temperature=kelvin)).temperature == 32767


# -- update_interim_state (_curr_mult) / send_battery_status (constrain_float) : current -----------------


@pytest.mark.parametrize(
    ("amps", "mult", "expected"),
    [(12.5, 1.0, 1250), (400.0, 1.0, 32767), (-400.0, 1.0, -32767), (10.0, 2.0, 2000), (math.inf, 1.0, 32767)],
)
def test_current_is_constrained_not_wrapped(amps: float, mult: float, expected: int) -> None:
    # current = constrain_float(current * 100, -INT16_MAX, INT16_MAX): above 327.67 A it saturates (PX4 wraps)
    scaled = F32(F32(mult) * F32(F16(amps)))
    assert ap(BatteryInfo(current=amps), curr_mult=mult).current_battery == expected
    if math.isfinite(float(scaled)):
        assert expected == c_int(float(max(F32(-32767), min(F32(32767), F32(scaled * 100)))), 16, True)


def test_nan_current_is_sent_as_zero_and_reported() -> None:
    # AP_Math constrain_value: NaN gives (low + high) / 2, here 0 cA: "no current" never reaches the GCS as -1
    report = LossReport()
    msg = dronecan_to_mavlink(BatteryInfo(current=math.nan), policy="ardupilot", report=report)
    assert msg.current_battery == 0
    assert ("unrepresentable", "mavlink.BATTERY_STATUS.current_battery") in [(e.kind, e.field) for e in report.entries]


# -- send_battery_status: cells -------------------------------------------------------------------------


def test_without_aux_the_pack_voltage_fills_the_cells_65534_mv_at_a_time() -> None:
    v = F32(F32(F16(70.0)) * F32(1e3))  # voltage_mV = gcs_voltage * 1e3f
    msg = ap(BatteryInfo(voltage=70.0))
    assert msg.voltages[:2] == [65534, c_int(float(F32(v - F32(65534))), 16, False)]
    assert msg.voltages[2:] == [65535] * 8  # voltage_mV < 0.001f: UINT16_MAX
    assert msg.voltages_ext == [0, 0, 0, 0]
    assert ap(BatteryInfo(voltage=16.4)).voltages == [16406] + [65535] * 9


def test_without_aux_a_nan_voltage_gives_65534_in_every_cell() -> None:
    # MIN(voltage_mV, max_cell_mV) is `a < b ? a : b`: NaN < 65534 is false, so every cell is 65534
    assert ap(BatteryInfo(voltage=math.nan)).voltages == [65534] * 10
    assert ap(BatteryInfo(voltage=0.0)).voltages == [65535] * 10


def test_with_aux_the_cells_are_millivolts_and_the_rest_of_the_pack_is_shared_out() -> None:
    cells = [4.1, 4.1, 4.1, 4.05]
    mv = [c_int(float(F32(F32(F16(c)) * F32(1000))), 16, False) for c in cells]  # cells[i] = data[i] * 1000
    pack = F32(F32(F16(16.4)) * F32(1e3))
    total = F32(0)
    for v in mv:
        total = F32(total + F32(v))
    extra = c_int(float(F32(F32(pack - total) / F32(len(mv)))), 32, False)  # uint32_t extra_mV
    msg = ap(BatteryInfo(voltage=16.4), BatteryInfoAux(voltage_cell=cells, nominal_voltage=14.8))
    assert msg.voltages == [v + extra for v in mv] + [0] * 6
    assert msg.voltages_ext == [0, 0, 0, 0]


def test_with_aux_at_most_14_cells_reach_voltages_and_voltages_ext() -> None:
    # handle_battery_info_aux: MIN(ARRAY_SIZE(cells), voltage_cell.len); cells 11..14 go to voltages_ext
    cells = [3.5 + i / 100 for i in range(16)]
    msg = ap(BatteryInfo(voltage=1.0), BatteryInfoAux(voltage_cell=cells))  # a pack below the cells' sum
    mv = [c_int(float(F32(F32(F16(c)) * F32(1000))), 16, False) for c in cells]
    assert msg.voltages == mv[:10] and msg.voltages_ext == mv[10:14]


# -- use_CAN_SoC / capacity_remaining_pct / battery_remaining_pct -------------------------------------


@pytest.mark.parametrize(("soc", "expected"), [(0, 0), (80, 80), (100, 100), (101, 100), (126, 100)])
def test_the_battery_soc_is_sent_constrained_to_100(soc: int, expected: int) -> None:
    # MIN(percentage, INT8_MAX) then constrain_int16(percentage, -1, 100)
    assert ap(BatteryInfo(state_of_charge_pct=soc)).battery_remaining == expected


def test_soc_127_or_the_ignore_option_uses_the_capacity_and_the_charge_consumed() -> None:
    # AP_BattMonitor_Backend::capacity_remaining_pct: 100 * (capacity - consumed) / capacity, in float, to uint8
    left = F32(3300 - F32(1234.5))
    expected = c_int(float(F32(F32(F32(100) * left) / F32(3300))), 8, False)
    assert ap(BatteryInfo(state_of_charge_pct=127), consumed_mah_before=1234.5).battery_remaining == expected == 62
    ignored = ap(BatteryInfo(state_of_charge_pct=80), consumed_mah_before=1234.5, options=1)  # BATT_OPTIONS bit 0
    assert ignored.battery_remaining == expected
    assert ap(BatteryInfo(state_of_charge_pct=127), capacity_mah=10).battery_remaining == -1  # <= 10 mAh: none
    over = ap(BatteryInfo(state_of_charge_pct=127), capacity_mah=1000, consumed_mah_before=1500)
    assert over.battery_remaining == 0  # constrain_float(..., 0, UINT8_MAX)


# -- update_consumed / calculate_mah ----------------------------------------------------------------------


def test_charge_is_counted_from_the_current_over_the_time_since_the_last_message() -> None:
    info = BatteryInfo(voltage=16.0, current=10.0, state_of_charge_pct=127)
    step = F32(F32(F32(10.0) * F32(500000)) * AUS_TO_MAH)  # calculate_mah(current_amps, dt_us)
    mah = F32(F32(100.0) + step)
    wh = F32(np.float64(F32(2.0)) + 0.001 * np.float64(step) * np.float64(F32(16.0)))  # 0.001 is a double
    report = LossReport()
    msg = dronecan_to_mavlink(
        info, policy="ardupilot", report=report, dt_s=0.5, consumed_mah_before=100.0, consumed_wh_before=2.0
    )
    assert msg.current_consumed == c_int(float(mah), 32, True)
    assert msg.energy_consumed == c_int(float(F32(wh * F32(36))), 32, True)  # consumed_wh *= 36: hJ
    assert report.carried == {"consumed_mah": float(mah), "consumed_wh": float(wh)}


def test_no_charge_is_counted_on_the_first_message_or_after_a_gap_of_2_s() -> None:
    info = BatteryInfo(current=10.0, state_of_charge_pct=127)
    # last_time_micros == 0 (the first message) or dt_us >= 2000000: nothing added
    assert ap(info, consumed_mah_before=100.0).current_consumed == 100
    assert ap(info, consumed_mah_before=100.0, dt_s=2.0).current_consumed == 100
    assert ap(info, consumed_mah_before=100.0, dt_s=1.999).current_consumed > 100


def test_with_aux_and_the_battery_soc_no_charge_is_counted() -> None:
    # update_interim_state: if (!_has_battery_info_aux || !use_CAN_SoC()) update_consumed(...)
    info = BatteryInfo(current=10.0, state_of_charge_pct=80)
    aux = BatteryInfoAux(nominal_voltage=math.nan)
    assert ap(info, aux, consumed_mah_before=100.0, dt_s=0.5).current_consumed == 100
    soc_unknown = BatteryInfo(current=10.0, state_of_charge_pct=127)
    assert ap(soc_unknown, aux, consumed_mah_before=100.0, dt_s=0.5).current_consumed == 101


# -- handle_battery_info_aux: consumed charge, energy and time from the energies -----------------------


def test_aux_with_a_nominal_voltage_sets_consumed_and_time_remaining() -> None:
    info = BatteryInfo(current=12.5, state_of_charge_pct=80, remaining_capacity_wh=40.0, full_charge_capacity_wh=80.0)
    nominal = F32(F16(14.8))
    rem_ah, full_ah = F32(F32(40.0) / nominal), F32(F32(80.0) / nominal)
    msg = ap(info, BatteryInfoAux(nominal_voltage=14.8))
    assert msg.current_consumed == c_int(float(F32(F32(full_ah - rem_ah) * F32(1000))), 32, True) == 2703
    assert msg.energy_consumed == c_int(float(F32(F32(80.0 - 40.0) * F32(36))), 32, True) == 1440
    assert msg.time_remaining == c_int(float(F32(F32(rem_ah / F32(12.5)) * F32(3600))), 32, False) == 778
    still = ap(BatteryInfo(current=0.0, remaining_capacity_wh=40.0), BatteryInfoAux(nominal_voltage=14.8))
    assert still.time_remaining == 0  # is_zero(current_amps) ? 0
    charging = ap(BatteryInfo(current=-5.0, remaining_capacity_wh=40.0), BatteryInfoAux(nominal_voltage=14.8))
    assert charging.time_remaining == 0  # a negative float into uint32_t: the FPU saturates to 0


def test_without_a_nominal_voltage_there_is_no_time_remaining() -> None:
    # time_remaining(): state.has_time_remaining is set only by handle_battery_info_aux with nominal_voltage > 0
    info = BatteryInfo(current=12.5, remaining_capacity_wh=40.0, full_charge_capacity_wh=80.0)
    assert ap(info).time_remaining == 0
    assert ap(info, BatteryInfoAux(nominal_voltage=math.nan)).time_remaining == 0
    assert ap(info, BatteryInfoAux(nominal_voltage=0.0)).time_remaining == 0


# -- the constant fields --------------------------------------------------------------------------------


def test_the_fields_ardupilot_fills_with_constants() -> None:
    msg = ap(BatteryInfo(battery_id=3, state_of_charge_pct=50))
    assert (msg.id, msg.battery_function, msg.type, msg.mode, msg.fault_bitmask) == (0, 0, 0, 0, 0)
    assert msg.charge_state == 1  # MAV_BATTERY_CHARGE_STATE_OK: failsafe None, healthy, no fault


# -- every conversion is a BATTERY_STATUS ArduPilot could send -------------------------------------------

_F16 = st.floats(width=16, allow_nan=True, allow_infinity=True)


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    info=st.builds(
        BatteryInfo,
        temperature=_F16,
        voltage=_F16,
        current=_F16,
        remaining_capacity_wh=_F16,
        full_charge_capacity_wh=_F16,
        state_of_charge_pct=st.integers(0, 127),
    ),
    aux=st.none() | st.builds(BatteryInfoAux, voltage_cell=st.lists(_F16, max_size=20), nominal_voltage=_F16),
    dt=st.none() | st.floats(0, 3),
    before=st.floats(-1e6, 1e6),
)
def test_every_conversion_packs_as_pymavlink_packs_it(
    info: BatteryInfo, aux: BatteryInfoAux | None, dt: float | None, before: float
) -> None:
    msg = ap(info, aux, dt_s=dt, consumed_mah_before=before) if dt is not None else ap(info, aux)
    assert msg.encode() == pymavlink_payload(msg)
    assert -1 <= msg.battery_remaining <= 100 and -32767 <= msg.current_battery <= 32767


def test_convert_carries_the_float_total_from_record_to_record(tmp_path: Path) -> None:
    # battgen convert feeds each record the monitor's float total (LossReport.carried), not the whole mAh it sent
    line = '{"info": {"voltage": 16.0, "current": 10.0, "state_of_charge_pct": 127}}\n'
    src = tmp_path / "stream.jsonl"
    src.write_text(line * 4, encoding="utf-8")
    args = ["--from", "dronecan", "--to", "mavlink", "--policy", "ardupilot", "--set", "dt_s=0.5", str(src)]
    done = subprocess.run(
        [sys.executable, "-m", "codegen", "convert", *args], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    step = F32(F32(F32(10.0) * F32(500000)) * AUS_TO_MAH)
    total, sent = F32(0), []
    for _ in range(4):
        total = F32(total + step)
        sent.append(c_int(float(total), 32, True))
    assert [json.loads(x)["current_consumed"] for x in done.stdout.splitlines()] == sent == [1, 2, 4, 5]
