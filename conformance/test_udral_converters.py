"""The UDRAL battery converters (schemas/mappings/udral.yaml) pinned to UDRAL's own text.

Each test quotes the sentence of the regulated types (../shared/corpus/cyphal/, upstream's DSDL comments)
that decides a conversion, checks that the corpus still says it, then converts as that sentence demands:
the sign of current, the state of charge from the available charge over the nominal capacity (and from the
energies), joules to watt-hours, coulombs to milliamp-hours, kelvin to degrees Celsius with 273.15, cells.
"""

from __future__ import annotations

import math
import re

import pytest
from shared_data import require, shared

from generated.convert import LossReport
from generated.convert.dronecan_udral import dronecan_to_udral, udral_to_dronecan
from generated.convert.udral import to_concepts as udral_to_concepts
from generated.convert.udral_mavlink import udral_to_mavlink
from generated.convert.udral_mavlink_info import mavlink_info_to_udral, udral_to_mavlink_info
from generated.convert.udral_mavlink_v2 import udral_to_mavlink_v2
from generated.convert.udral_uorb import udral_to_uorb, uorb_to_udral
from generated.cyphal.reg.udral.physics.electricity import SourceTs_0_1
from generated.cyphal.reg.udral.service.battery import Error_0_1Value, Parameters_0_3, Status_0_2
from generated.dronecan.uavcan.equipment.power import BatteryInfo, BatteryInfoStatusFlag
from generated.mavlink import MavBatteryFault
from generated.uorb import BatteryStatus, BatteryStatusFault


def udral_text(path: str) -> str:
    """A regulated type's comments as one line of prose (``#`` and line breaks dropped)."""
    text = require(shared("corpus", "cyphal", *path.split("/"))).read_text(encoding="utf-8")
    return " ".join(line.lstrip("#").strip() for line in text.splitlines())


def says(path: str, sentence: str) -> None:
    assert re.sub(r"\s+", " ", sentence) in udral_text(path), f"{path} no longer says: {sentence}"


def source(
    *, volt: float = 22.2, ampere: float = -12.5, joule: float = math.nan, full: float = math.nan
) -> SourceTs_0_1:
    s = SourceTs_0_1()
    s.value.power.voltage.volt = volt
    s.value.power.current.ampere = ampere
    s.value.energy.joule = joule
    s.value.full_energy.joule = full
    return s


def test_current_is_negative_when_the_battery_powers_the_system() -> None:
    says(
        "reg/udral/service/battery/_.0.1.dsdl",
        "Therefore, the current is negative when the battery powers the system, and positive when it is being charged.",
    )
    assert udral_to_concepts(source(ampere=-12.5)).current == 12.5  # the concept: positive discharging
    assert udral_to_uorb(source(ampere=-12.5)).current_a == 12.5  # PX4: positive discharging
    charging = udral_to_uorb(source(ampere=3.0))
    assert charging.current_a == -3.0
    back = uorb_to_udral(BatteryStatus(voltage_v=16.0, current_a=8.0))[0]
    assert back.value.power.current.ampere == -8.0


def test_state_of_charge_from_available_charge_over_nominal_capacity() -> None:
    says(
        "reg/udral/service/battery/Status.0.2.dsdl",
        "The depth of discharge (DoD), or the state of charge (SoC), can be derived by dividing this value by the "
        "nominal battery capacity reported in the Parameters message.",
    )
    status, parameters = Status_0_2(), Parameters_0_3()
    status.available_charge.coulomb = 3600.0 * 3.0  # 3 Ah left
    parameters.design_capacity.coulomb = 3600.0 * 4.0  # of 4 Ah
    state = udral_to_concepts(source(), status, parameters)
    assert state.state_of_charge == pytest.approx(0.75)
    out = udral_to_uorb(source(), status, parameters)
    assert out.remaining == pytest.approx(0.75)
    # PX4's capacity is the charge when full now, which UDRAL does not give (only when new): unknown
    assert out.capacity == 0
    # coulombs -> ampere-hours (MAVLink) by 3600, and back
    assert udral_to_mavlink_v2(source(), status).capacity_remaining == pytest.approx(3.0)
    assert udral_to_mavlink_info(source(), status, parameters).design_capacity == pytest.approx(4.0)
    back = mavlink_info_to_udral(udral_to_mavlink_info(source(), status, parameters))[2]
    assert back.design_capacity.coulomb == pytest.approx(14400.0)
    # without the Parameters message there is no capacity to divide by: unknown
    assert udral_to_concepts(source(), status).state_of_charge is None


def test_the_energy_ratio_wins_and_joules_become_watt_hours() -> None:
    says(
        "reg/udral/physics/electricity/Source.0.1.dsdl",
        "A pessimistic estimate of the amount of energy that can be reclaimed from the source in its current state.",
    )
    status, parameters = Status_0_2(), Parameters_0_3()
    status.available_charge.coulomb = 1000.0
    parameters.design_capacity.coulomb = 4000.0
    s = source(joule=3600.0 * 50.0, full=3600.0 * 100.0)  # 50 Wh of 100 Wh
    assert udral_to_concepts(s, status, parameters).state_of_charge == pytest.approx(0.5)
    out = udral_to_uorb(s, status, parameters)
    assert (out.remaining_capacity_wh, out.full_charge_capacity_wh) == (pytest.approx(50.0), pytest.approx(100.0))
    info = udral_to_dronecan(s, status, parameters)[0]
    assert (info.remaining_capacity_wh, info.full_charge_capacity_wh) == (50.0, 100.0)


def test_kelvin_become_celsius_with_273_15() -> None:
    says(
        "reg/udral/service/battery/Status.0.2.dsdl",
        "The minimum and maximum readings of the pack temperature sensors.",
    )
    status = Status_0_2()
    status.temperature_min_max[0].kelvin = 288.15
    status.temperature_min_max[1].kelvin = 313.15
    out = udral_to_uorb(source(), status)
    assert out.temperature == pytest.approx(40.0)  # the hottest sensor, 273.15 K off (not NXP's 272.15)
    assert udral_to_dronecan(source(), status)[0].temperature == pytest.approx(
        313.15, abs=0.125
    )  # float16: steps of 0.25 K


def test_cells_and_their_count() -> None:
    says("reg/udral/service/battery/Status.0.2.dsdl", "The voltages of individual cells in the battery pack.")
    status, parameters = Status_0_2(), Parameters_0_3()
    status.cell_voltages = [4.0, 4.1, 3.9]
    parameters.series_cell_count = 3
    out = udral_to_uorb(source(), status, parameters)
    assert out.cell_count == 3
    assert list(out.voltage_cell_v[:3]) == [4.0, pytest.approx(4.1, abs=1e-6), pytest.approx(3.9, abs=1e-6)]


def test_nan_is_unknown_and_reported() -> None:
    report = LossReport()
    out = udral_to_uorb(source(volt=math.nan, ampere=math.nan), report=report)
    assert out.voltage_v == 0 and out.current_a == -1  # PX4's own markers of unknown
    assert out.remaining == -1
    assert "uorb.BatteryStatus.voltage_v" in {e.field for e in report.entries}


def test_round_trip_through_uorb_keeps_the_values() -> None:
    status, parameters = Status_0_2(), Parameters_0_3()
    status.temperature_min_max[1].kelvin = 300.0
    parameters.series_cell_count = 6
    s = source(volt=24.0, ampere=-20.0)
    back_source, back_status, back_parameters = uorb_to_udral(udral_to_uorb(s, status, parameters))
    assert back_source.value.power.voltage.volt == 24.0
    assert back_source.value.power.current.ampere == -20.0
    assert back_status.temperature_min_max[1].kelvin == pytest.approx(300.0, abs=1e-4)
    assert back_parameters.series_cell_count == 6
    # every UDRAL object a converter writes serializes as pydsdl expects (the codec under the converters)
    assert SourceTs_0_1.decode(back_source.encode()) == back_source


# UDRAL Error value -> (its comment in Error.0.1, uORB fault, DroneCAN status flag, MAVLink fault bit)
ERRORS = {
    "BAD_BATTERY": ("The battery should not be used anymore.", "HARDWARE_FAILURE", "BAD_BATTERY", None),
    "OVERDISCHARGE": (
        "The battery is discharged beyond the design limits",
        "DEEP_DISCHARGE",
        None,
        "DEEP_DISCHARGE",
    ),
    "OVERLOAD": (
        "The charge or discharge rate exceeds the safe operating limits.",
        "OVER_CURRENT",
        "OVERLOAD",
        "OVER_CURRENT",
    ),
    "TEMPERATURE_HOT": (
        "At least one cell is above/below the temperature SOA.",
        "OVER_TEMPERATURE",
        "TEMP_HOT",
        "OVER_TEMPERATURE",
    ),
    "TEMPERATURE_COLD": (
        "At least one cell is above/below the temperature SOA.",
        "UNDER_TEMPERATURE",
        "TEMP_COLD",
        "UNDER_TEMPERATURE",
    ),
}


def _status(error: str) -> Status_0_2:
    status = Status_0_2()
    status.error.value = getattr(Error_0_1Value, error)
    return status


@pytest.mark.parametrize("error", sorted(ERRORS))
def test_errors_become_the_faults_of_every_other_format(error: str) -> None:
    comment, uorb_fault, dronecan_flag, mavlink_fault = ERRORS[error]
    says("reg/udral/service/battery/Error.0.1.dsdl", comment)
    faults = udral_to_uorb(source(), _status(error)).faults
    assert faults == 1 << getattr(BatteryStatusFault, uorb_fault)  # uORB's FAULT_* are bit positions
    flags = udral_to_dronecan(source(), _status(error))[0].status_flags
    assert flags == (BatteryInfoStatusFlag[dronecan_flag] if dronecan_flag else 0)
    bitmask = udral_to_mavlink(source(), _status(error)).fault_bitmask
    assert bitmask == (getattr(MavBatteryFault, mavlink_fault).value if mavlink_fault else 0)


@pytest.mark.parametrize(
    ("error", "comment"),
    [
        ("NEEDS_SERVICE", "The battery requires offline maintenance."),
        ("BMS_ERROR", "An internal error in the battery management system, not related to the battery itself."),
        ("CONFIGURATION", "The battery/BMS/node/service configuration is missing or invalid."),
        ("CELL_UNDERVOLTAGE", "Voltage of one of the battery cells exceeds its SOA."),
        ("CELL_COUNT", "The sum of cell voltages is far from the total pack voltage."),
    ],
)
def test_errors_without_a_fault_are_reported_dropped(error: str, comment: str) -> None:
    says("reg/udral/service/battery/Error.0.1.dsdl", comment)
    report = LossReport()
    assert udral_to_uorb(source(), _status(error), report=report).faults == 0
    dropped = [e for e in report.entries if e.field.endswith("Status_0_2.error.value")]
    assert [e.kind for e in dropped] == ["dropped"]


def test_the_most_severe_fault_is_the_error_written() -> None:
    """UDRAL's Error holds one condition: of several faults, the one of the smallest code, the others dropped."""
    says(
        "reg/udral/service/battery/Error.0.1.dsdl",
        "it is recommended to give preference to errors whose code is smaller "
        "(e.g., BAD_BATTERY trumps TEMPERATURE_COLD).",
    )
    report = LossReport()
    faults = 1 << BatteryStatusFault.OVER_TEMPERATURE | 1 << BatteryStatusFault.DEEP_DISCHARGE
    status = uorb_to_udral(BatteryStatus(faults=faults), report=report)[1]
    assert status.error.value == Error_0_1Value.OVERDISCHARGE
    assert [e.detail for e in report.entries if e.field == "concepts.faults"] == [
        "over_temperature not written: one condition at a time"
    ]
    info = BatteryInfo(status_flags=BatteryInfoStatusFlag.BAD_BATTERY | BatteryInfoStatusFlag.TEMP_COLD)
    assert dronecan_to_udral(info)[1].error.value == Error_0_1Value.BAD_BATTERY
    assert uorb_to_udral(BatteryStatus())[1].error.value == Error_0_1Value.NONE
