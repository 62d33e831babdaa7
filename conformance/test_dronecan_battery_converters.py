"""The battery messages ArduPilot and PX4 use today (ArduPilot's BatteryContinuous, BatteryPeriodic,
BatteryCells, BatteryTag; CUAV's CBAT) converted to the shared concepts, against pydronecan.

pydronecan encodes random values; our generated class decodes the bytes; the converter's concepts
must equal pydronecan's own decoding of the same bytes, in SI units (the factors are the DSDL
comments' units, and for CBAT those PX4's bridge reads it with: mAh, minutes, a negative discharge).
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

dronecan = pytest.importorskip("dronecan")
from dronecan import transport  # noqa: E402

from generated.convert import (  # noqa: E402
    ardupilot_battery,
    cbat,
    cbat_uorb,
)
from generated.dronecan.ardupilot.equipment import power as ap_power  # noqa: E402
from generated.dronecan.cuav.equipment import power as cuav_power  # noqa: E402

F16 = st.one_of(st.floats(-1000, 1000, width=16), st.just(math.nan))
F32 = st.one_of(st.floats(-1e6, 1e6, width=32), st.just(math.nan))


def _wire(ref: Any, ours: type) -> tuple[Any, Any]:
    """The bytes pydronecan packs, decoded by pydronecan and by our class."""
    data = bytes(transport.bytes_from_bits(ref._pack()))
    back = transport.CompoundValue(ref._type)
    back._unpack(transport.bits_from_bytes(data))
    return back, ours.decode(data)  # type: ignore[attr-defined]


def _same(ours: float | None, expected: float | None) -> bool:
    if expected is None or ours is None:
        return ours is expected
    if math.isnan(expected):
        return math.isnan(ours)
    return math.isclose(ours, expected, rel_tol=1e-12, abs_tol=1e-12)


def _unknown_if(value: float, *markers: float) -> float | None:
    if math.isnan(value) or value in markers:
        return None
    return value


def _ref(type_name: str, **values: Any) -> Any:
    namespace = dronecan.cuav.equipment.power if type_name == "CBAT" else dronecan.ardupilot.equipment.power
    obj = getattr(namespace, type_name)()
    for key, value in values.items():
        setattr(obj, key, value)
    return obj


@settings(max_examples=120, deadline=None)
@given(
    voltage=F32, current=F32, t_cells=F16, soc=F16, slot=st.integers(0, 255), consumed=F32,
    flags=st.integers(0, (1 << 19) - 1), design=F32, full=F32, n_series=st.integers(0, 255), nominal=F16,
    cycles=st.integers(0, 65535), soh=st.integers(0, 255), name=st.binary(max_size=50),
    cells=st.lists(st.floats(0, 5, width=16), max_size=24), serial=st.integers(0, 2**32 - 1),
)  # fmt: skip
def test_ardupilot_battery_concepts_equal_pydronecans_values(
    voltage: float, current: float, t_cells: float, soc: float, slot: int, consumed: float, flags: int,
    design: float, full: float, n_series: int, nominal: float, cycles: int, soh: int, name: bytes,
    cells: list[float], serial: int,
) -> None:  # fmt: skip
    c_ref, c = _wire(_ref("BatteryContinuous", voltage=voltage, current=current, temperature_cells=t_cells,
                          state_of_charge=soc, slot_id=slot, capacity_consumed=consumed, status_flags=flags),
                     ap_power.BatteryContinuous)  # fmt: skip
    p_ref, p = _wire(_ref("BatteryPeriodic", design_capacity=design, full_charge_capacity=full, name=name,
                          cells_in_series=n_series, nominal_voltage=nominal, cycle_count=cycles, state_of_health=soh),
                     ap_power.BatteryPeriodic)  # fmt: skip
    v_ref, v = _wire(_ref("BatteryCells", voltages=cells, index=0), ap_power.BatteryCells)
    t_ref, t = _wire(_ref("BatteryTag", serial_number=serial), ap_power.BatteryTag)
    state = ardupilot_battery.to_concepts(c, p, v, t)
    assert _same(state.pack_voltage, _unknown_if(c_ref.voltage))
    assert _same(state.current, _unknown_if(c_ref.current))
    temp = _unknown_if(c_ref.temperature_cells)
    assert _same(state.temperature, None if temp is None else temp + 273.15)  # degrees Celsius -> kelvin
    percent = _unknown_if(c_ref.state_of_charge)
    assert _same(state.state_of_charge, None if percent is None or percent > 100 else percent / 100)
    ah = _unknown_if(c_ref.capacity_consumed)
    assert _same(state.discharged, None if ah is None else ah * 3600.0)
    assert state.battery_index == (c_ref.slot_id - 1 if c_ref.slot_id else None)
    assert state.charging == bool(c_ref.status_flags & 2)
    assert ("over_current" in (state.faults or ())) == bool(c_ref.status_flags & 8192)
    assert ("deep_discharge" in (state.faults or ())) == bool(c_ref.status_flags & 1024)
    design_ah = _unknown_if(p_ref.design_capacity, 0.0)
    assert _same(state.design_capacity, None if design_ah is None else design_ah * 3600.0)
    full_ah = _unknown_if(p_ref.full_charge_capacity)
    assert _same(state.full_capacity, None if full_ah is None else full_ah * 3600.0)
    assert state.cell_count == (p_ref.cells_in_series or None)
    assert _same(state.nominal_voltage, _unknown_if(p_ref.nominal_voltage, 0.0))
    assert state.cycle_count == (None if p_ref.cycle_count == 65535 else p_ref.cycle_count)
    assert _same(state.state_of_health, None if p_ref.state_of_health > 100 else p_ref.state_of_health / 100)
    assert state.model_name == (bytes(p_ref.name).split(b"\0")[0].decode("utf-8", "replace") or None)
    assert state.cell_voltages is None or list(state.cell_voltages) == [float(x) for x in v_ref.voltages]
    assert state.serial_number == (t_ref.serial_number or None)


@settings(max_examples=120, deadline=None)
@given(
    voltage=F32, current=F32, average=F32, temperature=F32, soc=st.integers(0, 127), soh=st.integers(0, 127),
    full=F32, design=F32, to_empty=st.integers(0, 65535), to_full=st.integers(0, 65535), nominal=F32,
    cells=st.lists(st.floats(0, 5, width=32), max_size=15), flags=st.integers(0, 2047),
    cycles=st.integers(0, 65535), serial=st.integers(0, 65535), off=st.booleans(),
)  # fmt: skip
def test_cbat_concepts_equal_pydronecans_values(
    voltage: float, current: float, average: float, temperature: float, soc: int, soh: int, full: float,
    design: float, to_empty: int, to_full: int, nominal: float, cells: list[float], flags: int, cycles: int,
    serial: int, off: bool,
) -> None:  # fmt: skip
    ref, ours = _wire(_ref("CBAT", voltage=voltage, current=current, average_current=average, temperature=temperature,
                           state_of_charge=soc, state_of_health=soh, full_charge_capacity=full, design_capacity=design,
                           average_time_to_empty=to_empty, average_time_to_full=to_full, nominal_voltage=nominal,
                           voltage_cell=cells, cell_count=len(cells), status_flags=flags, cycle_count=cycles,
                           serial_number=serial, is_powering_off=off),
                      cuav_power.CBAT)  # fmt: skip
    state = cbat.to_concepts(ours)
    assert _same(state.pack_voltage, ref.voltage)
    assert _same(state.current, -ref.current)  # discharge negative on the wire, positive as a concept
    assert _same(state.average_current, -ref.average_current)
    assert _same(state.temperature, ref.temperature if ref.temperature > 0 else None)
    assert _same(state.state_of_charge, ref.state_of_charge / 100 if ref.state_of_charge <= 100 else None)
    assert _same(state.state_of_health, ref.state_of_health / 100 if ref.state_of_health <= 100 else None)
    mah = 3.6  # coulombs per mAh
    assert _same(state.full_capacity, ref.full_charge_capacity * mah if ref.full_charge_capacity != 0 else None)
    assert _same(state.design_capacity, ref.design_capacity * mah if ref.design_capacity != 0 else None)
    assert _same(state.time_remaining, ref.average_time_to_empty * 60.0 if ref.average_time_to_empty != 65535 else None)
    assert _same(state.time_to_full, ref.average_time_to_full * 60.0 if ref.average_time_to_full != 65535 else None)
    assert _same(state.nominal_voltage, _unknown_if(ref.nominal_voltage, 0.0))
    assert list(state.cell_voltages or ()) == [float(x) for x in ref.voltage_cell]
    assert (state.cell_count, state.cycle_count, state.serial_number) == (ref.cell_count, ref.cycle_count,
                                                                           ref.serial_number)  # fmt: skip
    assert state.is_powering_off == bool(ref.is_powering_off)
    assert state.in_use == bool(ref.status_flags & 1) and state.charging == bool(ref.status_flags & 2)
    faults = set(state.faults or ())
    assert ("over_current" in faults, "hardware_failure" in faults) == (bool(flags & 32), bool(flags & 64))
    assert ("over_temperature" in faults, "under_temperature" in faults) == (bool(flags & 8), bool(flags & 16))


def test_cbat_reaches_uorb_through_the_concepts() -> None:
    data = _ref("CBAT", voltage=15.2, current=-8.0, temperature=300.0, state_of_charge=55, cell_count=4,
                voltage_cell=[3.8, 3.8, 3.8, 3.8], full_charge_capacity=5000.0)  # fmt: skip
    status = cbat_uorb.cbat_to_uorb(cuav_power.CBAT.decode(bytes(transport.bytes_from_bits(data._pack()))))
    assert (status.voltage_v, status.current_a, status.remaining) == (pytest.approx(15.2), 8.0, pytest.approx(0.55))
    assert status.temperature == pytest.approx(300.0 - 273.15, abs=1e-4)  # uORB holds degrees Celsius
    assert status.cell_count == 4 and status.capacity == 5000  # mAh
