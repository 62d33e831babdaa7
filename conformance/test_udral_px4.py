"""The ``px4`` policy from UDRAL to uORB (schemas/mappings/px4_cyphal_battery.yaml) against what PX4's Cyphal
battery subscriber does (src/drivers/cyphal/Subscribers/udral/Battery.hpp, UavcanBmsSubscriber::callback),
beside the strict converter that does what UDRAL means, so each departure shows as a difference:

* ``current_a = ampere``: no sign flip, a discharge (negative in UDRAL) stays negative;
* ``remaining = energy / full_energy`` unchecked, NaN when either is unknown;
* ``discharged_mah = (full_energy - energy) / (nominal_voltage * 3600)``: ampere-hours in a mAh field, and NaN
  without a nominal voltage (its ``!= NAN`` test is always true);
* ``temperature = temperature_min_max[1] - 273.15f``, ``capacity = design_capacity / 3.6f``, ``scale = -1``,
  ``max_error = 1``, ``id = 0``, ``connected = true``.
"""

from __future__ import annotations

import math

import pytest

from generated.convert.udral_uorb import udral_to_uorb
from generated.cyphal.reg.udral.physics.electricity import SourceTs_0_1
from generated.cyphal.reg.udral.service.battery import Parameters_0_3, Status_0_2


def battery(
    *, ampere: float = -10.0, joule: float = 180000.0, full: float = 360000.0, nominal: float = 25.0
) -> tuple[SourceTs_0_1, Status_0_2, Parameters_0_3]:
    source, status, parameters = SourceTs_0_1(), Status_0_2(), Parameters_0_3()
    source.value.power.voltage.volt = 24.5
    source.value.power.current.ampere = ampere
    source.value.energy.joule = joule
    source.value.full_energy.joule = full
    status.temperature_min_max[0].kelvin = 293.15
    status.temperature_min_max[1].kelvin = 313.15
    parameters.design_capacity.coulomb = 14400.0
    parameters.nominal_voltage.volt = nominal
    parameters.cycle_count = 12
    parameters.state_of_health_pct = 97
    return source, status, parameters


def test_the_current_keeps_udral_sign() -> None:
    px4 = udral_to_uorb(*battery(ampere=-10.0), policy="px4")
    strict = udral_to_uorb(*battery(ampere=-10.0))
    assert px4.current_a == -10.0  # PX4: a discharge reported as a charge
    assert strict.current_a == 10.0


def test_remaining_is_the_unchecked_energy_ratio() -> None:
    assert udral_to_uorb(*battery(joule=90000.0), policy="px4").remaining == 0.25
    unknown = udral_to_uorb(*battery(joule=math.nan), policy="px4")
    assert math.isnan(unknown.remaining)
    assert udral_to_uorb(*battery(joule=math.nan)).remaining == -1  # strict: uORB's unknown marker


def test_discharged_is_ampere_hours_in_a_milliamp_hour_field() -> None:
    # 50 Wh drawn of a 25 V pack: 2 Ah, which PX4 stores as 2 "mAh"
    assert udral_to_uorb(*battery(), policy="px4").discharged_mah == pytest.approx(2.0)
    source, status, _ = battery()
    assert math.isnan(udral_to_uorb(source, status, policy="px4").discharged_mah)  # no Parameters yet
    assert math.isnan(udral_to_uorb(*battery(nominal=math.nan), policy="px4").discharged_mah)


def test_the_fields_px4_copies() -> None:
    px4 = udral_to_uorb(*battery(), policy="px4")
    assert px4.temperature == pytest.approx(40.0, abs=1e-4)
    assert px4.capacity == 4000  # 14400 C / 3.6
    assert (px4.cycle_count, px4.state_of_health) == (12, 97)
    assert (px4.scale, px4.max_error, px4.id, px4.connected) == (-1.0, 1, 0, True)
    assert px4.voltage_v == 24.5


def test_px4_sets_no_fault_from_the_error() -> None:
    """Battery.hpp's Status callback copies the temperature and the cells and never reads ``error``: an
    over-temperature UDRAL reports reaches PX4 as no fault (and the loss report names the error dropped), where
    the strict converter sets FAULT_OVER_TEMPERATURE."""
    from generated.convert import LossReport
    from generated.cyphal.reg.udral.service.battery import Error_0_1Value
    from generated.uorb import BatteryStatusFault

    source, status, parameters = battery()
    status.error.value = Error_0_1Value.TEMPERATURE_HOT
    report = LossReport()
    px4 = udral_to_uorb(source, status, parameters, policy="px4", report=report)
    assert px4.faults == 0
    assert ("cyphal.reg.udral.service.battery.Status_0_2.error", "dropped") in {
        (e.field, e.kind) for e in report.entries
    }
    assert udral_to_uorb(source, status, parameters).faults == 1 << BatteryStatusFault.OVER_TEMPERATURE
