"""The px4 policy's estimates from PX4's uavcan battery bridge, pinned to its source.

PX4-Autopilot ``src/drivers/uavcan/sensors/battery.cpp``: ``UavcanBatteryBridge::battery_sub_cb``
(raw mode: ``discharged_mah = _battery[instance]->sumDischarged(fabsf(msg.current))`` after
``updateDt``, ``time_remaining_s = NAN``) and ``UavcanBatteryBridge::battery_aux_sub_cb``
(``setCapacityMah(capacity)``, ``setStateOfCharge(remaining)``, ``time_remaining_s =
computeRemainingTime(fabsf(current_a))``, ``current_average_a = getCurrentAverage()``), with
``src/lib/battery/battery.cpp``: ``Battery::updateDt`` (dt capped at 2 s), ``Battery::sumDischarged``
and ``Battery::computeRemainingTime`` (the average-current filter reset to ``BAT_AVRG_CURRENT``,
15 A by default, and updated only while armed). The arithmetic is recomputed here with numpy's
float32, a second implementation of the C code independent of the generated runtime.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from generated.convert.dronecan_uorb import dronecan_to_uorb
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo

F32, F16 = np.float32, np.float16
FLT_EPSILON = F32(1.1920928955078125e-07)
BAT_AVRG_CURRENT = F32(15.0)


def sum_discharged(total: np.float32, current: float, dt: float | None) -> np.float32:
    """Battery::updateDt then Battery::sumDischarged(fabsf(msg.current)), in float32."""
    step = F32(0.0) if dt is None else min(F32(dt), F32(2.0))
    if step > FLT_EPSILON:
        loop = F32(F32(abs(F32(F16(current))) * F32(1e3)) * F32(step / F32(3600.0)))
        total = F32(total + loop)
    return total


@settings(max_examples=60, deadline=None)
@given(
    currents=st.lists(st.floats(-300, 300, width=16), min_size=1, max_size=12),
    dts=st.lists(st.one_of(st.none(), st.floats(0, 5, width=32)), min_size=12, max_size=12),
)
def test_raw_mode_integrates_discharged_mah_over_a_stream(currents: list[float], dts: list[float | None]) -> None:
    total, ours = F32(0.0), None
    for i, current in enumerate(currents):
        dt = None if i == 0 else dts[i]  # the first message: updateDt has no previous timestamp
        total = sum_discharged(total, current, dt)
        status = dronecan_to_uorb(
            BatteryInfo(current=current), policy="px4", dt_s=dt, discharged_mah_before=ours
        )  # fmt: skip
        ours = status.discharged_mah
        assert ours == float(total)
        assert math.isnan(status.time_remaining_s) and status.current_average_a == 0.0


def test_raw_mode_caps_dt_at_two_seconds_and_counts_a_charge_as_discharge() -> None:
    one = dronecan_to_uorb(BatteryInfo(current=36.0), policy="px4", dt_s=10.0, discharged_mah_before=100.0)
    assert one.discharged_mah == float(F32(100.0) + F32(F32(36.0 * 1e3) * F32(F32(2.0) / F32(3600.0))))  # 120 mAh
    assert one.discharged_mah == 120.0
    charging = dronecan_to_uorb(BatteryInfo(current=-36.0), policy="px4", dt_s=1.0)
    assert charging.discharged_mah == 10.0  # fabsf(msg.current)
    first = dronecan_to_uorb(BatteryInfo(current=36.0), policy="px4")
    assert first.discharged_mah == 0.0  # no dt yet


@settings(max_examples=80, deadline=None)
@given(
    soc=st.integers(0, 127),
    full_wh=st.floats(0, 2000, width=16),
    nominal=st.floats(0, 60, width=16),
    current=st.floats(-200, 200, width=16),
    before=st.one_of(st.none(), st.floats(0, 1e5, width=32)),
)
def test_with_aux_time_remaining_and_average_current(
    soc: int, full_wh: float, nominal: float, current: float, before: float | None
) -> None:
    info = BatteryInfo(state_of_charge_pct=soc, full_charge_capacity_wh=full_wh, current=current)
    status = dronecan_to_uorb(info, BatteryInfoAux(nominal_voltage=nominal), policy="px4",
                              dt_s=1.0, discharged_mah_before=before)  # fmt: skip
    remaining = F32(soc) / F32(100.0)
    capacity = 0  # battery_status.capacity: zero unless the aux callback sets it (uint16)
    if F32(F16(nominal)) > FLT_EPSILON:
        mah = F32(F32(F32(F16(full_wh)) * F32(1000.0)) / F32(F16(nominal)))
        capacity = int(np.uint16(min(max(math.trunc(float(mah)), 0), 2**32 - 1) & 0xFFFF)) if math.isfinite(mah) else 0
    assert status.capacity == capacity
    assert status.current_average_a == float(BAT_AVRG_CURRENT)  # getCurrentAverage(): disarmed, the reset value
    if capacity > 0:
        current_ma = max(F32(BAT_AVRG_CURRENT * F32(1e3)), FLT_EPSILON)
        expected = F32(F32(F32(remaining * F32(capacity)) / current_ma) * F32(3600.0))
        assert status.time_remaining_s == float(expected)
    else:
        assert math.isnan(status.time_remaining_s)  # computeRemainingTime without a capacity
    # RawAux mode: battery_sub_cb no longer integrates; the total so far stays
    assert status.discharged_mah == (0.0 if before is None else float(F32(before)))


def test_a_pack_with_aux_reports_minutes_left_at_the_default_average_current() -> None:
    info = BatteryInfo(state_of_charge_pct=50, full_charge_capacity_wh=96.0, current=10.0)  # float16-exact values
    status = dronecan_to_uorb(info, BatteryInfoAux(nominal_voltage=24.0), policy="px4")
    assert status.capacity == 4000  # 96 Wh / 24 V, in mAh
    # 0.5 * 4000 mAh / 15000 mA * 3600 s, in float32 (2000 / 15000 rounds up a little)
    assert status.time_remaining_s == float(F32(F32(F32(2000.0) / F32(15000.0)) * F32(3600.0))) == 480.0000305175781
    assert status.current_average_a == 15.0
