"""The generated converters (strict policy, round trips, loss reports) and the generator's safety.

The px4-policy rules are pinned in conformance/test_converters_px4.py.
"""

from __future__ import annotations

import math
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT
from hypothesis import given, settings
from hypothesis import strategies as st

from codegen.frontends import mappings
from codegen.frontends.loader import load
from generated.convert import (
    CONVERTERS,
    ENDPOINTS,
    POLICIES,
    BatteryState,
    ConversionError,
    LossReport,
    _cells,
    converter,
)
from generated.convert import _runtime as rt
from generated.convert.dronecan import from_concepts as dronecan_from_concepts
from generated.convert.dronecan import to_concepts as dronecan_to_concepts
from generated.convert.dronecan_mavlink import dronecan_to_mavlink, mavlink_to_dronecan
from generated.convert.dronecan_uorb import dronecan_to_uorb, uorb_to_dronecan
from generated.convert.uorb_devicetree import devicetree_to_uorb
from generated.convert.uorb_mavlink import mavlink_to_uorb, uorb_to_mavlink
from generated.convert.uorb_uorb_v0 import uorb_to_uorb_v0, uorb_v0_to_uorb
from generated.devicetree import SimpleBattery
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo, BatteryInfoStatusFlag
from generated.mavlink import BatteryStatus as MavBatteryStatus
from generated.uorb import BatteryStatus, BatteryStatusFault, BatteryStatusState, BatteryStatusV0

NAN = math.nan


def f16(x: float) -> float:
    value: float = struct.unpack("<e", struct.pack("<e", x))[0]
    return value


def same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b


# -- the registry and API ------------------------------------------------------------------


def test_every_pair_of_the_issue_has_a_converter_with_both_policies() -> None:
    pairs = [("dronecan", "uorb"), ("uorb", "dronecan"), ("uorb", "mavlink"), ("mavlink", "uorb")]
    pairs += [("dronecan", "mavlink"), ("mavlink", "dronecan"), ("uorb_v0", "uorb"), ("uorb", "uorb_v0")]
    for pair in pairs:
        # ArduPilot's own code path exists for DroneCAN -> MAVLink only (its DroneCAN battery monitor)
        expected = ("strict", "px4", "ardupilot") if pair == ("dronecan", "mavlink") else ("strict", "px4")
        assert POLICIES[pair] == expected, pair
    assert POLICIES[("devicetree", "uorb")] == ("strict",)
    assert POLICIES[("devicetree", "dronecan")] == ("strict",)
    assert converter("dronecan", "uorb") is dronecan_to_uorb
    assert [a for a, _ in ENDPOINTS["dronecan"]] == ["info", "aux"]


def test_unknown_pair_and_policy_are_clear_errors() -> None:
    with pytest.raises(ConversionError, match="no converter from 'uorb' to 'nowhere'"):
        converter("uorb", "nowhere")
    with pytest.raises(ConversionError, match="unknown policy 'lenient'"):
        dronecan_to_uorb(BatteryInfo(), policy="lenient")
    with pytest.raises(ConversionError, match="no px4 behaviour converts devicetree to uorb"):
        devicetree_to_uorb(SimpleBattery(), policy="px4")
    assert ("devicetree", "dronecan") in CONVERTERS and ("uorb", "devicetree") not in CONVERTERS


# -- strict semantics ----------------------------------------------------------------------


def test_strict_soc_127_and_soh_127_are_unknown() -> None:
    report = LossReport()
    out = dronecan_to_uorb(BatteryInfo(state_of_charge_pct=127, state_of_health_pct=127, voltage=NAN), report=report)
    assert out.remaining == -1.0 and out.state_of_health == 0 and out.voltage_v == 0.0
    assert {"uorb.BatteryStatus.remaining", "uorb.BatteryStatus.state_of_health"} <= set(report.fields("unknown"))


def test_strict_kelvin_to_celsius_with_non_physical_unknown() -> None:
    assert (
        dronecan_to_uorb(BatteryInfo(temperature=298.25)).temperature == struct.unpack("<f", struct.pack("<f", 25.1))[0]
    )
    assert math.isnan(dronecan_to_uorb(BatteryInfo(temperature=0.0)).temperature)
    assert math.isnan(dronecan_to_uorb(BatteryInfo(temperature=-5.0)).temperature)
    assert math.isnan(dronecan_to_uorb(BatteryInfo(temperature=NAN)).temperature)


def test_strict_battery_id_is_0_based_in_dronecan_1_based_in_uorb() -> None:
    assert dronecan_to_uorb(BatteryInfo(battery_id=0)).id == 1
    assert uorb_to_dronecan(BatteryStatus(id=3))[0].battery_id == 2
    info, _ = uorb_to_dronecan(BatteryStatus(id=0), report=(r := LossReport()))
    assert info.battery_id == 0 and "dronecan.uavcan.equipment.power.BatteryInfo.battery_id" in r.fields("unknown")


def test_strict_state_of_charge_hybrid_rule() -> None:
    both = BatteryInfo(remaining_capacity_wh=25.0, full_charge_capacity_wh=100.0, state_of_charge_pct=90)
    assert dronecan_to_uorb(both).remaining == 0.25
    pct_only = BatteryInfo(remaining_capacity_wh=NAN, full_charge_capacity_wh=100.0, state_of_charge_pct=90)
    assert dronecan_to_uorb(pct_only).remaining == pytest.approx(0.9)
    zero_full = BatteryInfo(remaining_capacity_wh=5.0, full_charge_capacity_wh=0.0, state_of_charge_pct=127)
    assert dronecan_to_uorb(zero_full).remaining == -1.0


def test_strict_status_flags_to_faults_and_warning() -> None:
    flags = BatteryInfoStatusFlag.TEMP_HOT | BatteryInfoStatusFlag.OVERLOAD | BatteryInfoStatusFlag.BAD_BATTERY
    report = LossReport()
    out = dronecan_to_uorb(BatteryInfo(status_flags=flags | BatteryInfoStatusFlag.NEED_SERVICE), report=report)
    expected = {
        BatteryStatusFault.OVER_TEMPERATURE,
        BatteryStatusFault.OVER_CURRENT,
        BatteryStatusFault.HARDWARE_FAILURE,
    }
    assert out.faults == sum(1 << b for b in expected)
    assert report.entries[0].to_dict() == {
        "kind": "dropped",
        "field": "dronecan.uavcan.equipment.power.BatteryInfo.status_flags",
        "detail": "bits 0x80 have no counterpart",
    }
    cold = dronecan_to_uorb(BatteryInfo(status_flags=BatteryInfoStatusFlag.TEMP_COLD))
    assert cold.faults == 1 << BatteryStatusFault.UNDER_TEMPERATURE
    charging = dronecan_to_uorb(BatteryInfo(status_flags=BatteryInfoStatusFlag.CHARGING))
    assert charging.warning == BatteryStatusState.CHARGING
    assert mavlink_to_dronecan(MavBatteryStatus(charge_state=7))[0].status_flags & BatteryInfoStatusFlag.CHARGING


def test_sentinels_map_to_sentinels() -> None:
    mav = uorb_to_mavlink(BatteryStatus())
    assert (mav.temperature, mav.current_battery, mav.battery_remaining, mav.current_consumed) == (32767, -1, -1, -1)
    assert mav.voltages == [65535] * 10 and mav.voltages_ext == [0] * 4 and mav.time_remaining == 0
    info, aux = uorb_to_dronecan(BatteryStatus())
    assert math.isnan(info.voltage) and math.isnan(info.temperature) and info.state_of_charge_pct == 127
    assert aux.voltage_cell == [] and aux.nominal_voltage == 0.0  # "zero disables the conversion"


# -- loss reports ----------------------------------------------------------------------------


def test_loss_report_pins_float16_rounding_and_overflow() -> None:
    report = LossReport()
    info, _ = uorb_to_dronecan(BatteryStatus(voltage_v=12.345, temperature=25.0, current_a=70000.0), report=report)
    assert info.voltage == f16(12.345) and info.current == 65504.0
    kinds = {(e.kind, e.field) for e in report}
    assert ("rounded", "dronecan.uavcan.equipment.power.BatteryInfo.voltage") in kinds
    assert ("clamped", "dronecan.uavcan.equipment.power.BatteryInfo.current") in kinds
    assert ("dropped", "uorb.BatteryStatus.scale") not in kinds  # -1 is its default: nothing was lost


def test_loss_report_pins_centiamp_overflow_and_14_cells() -> None:
    report = LossReport()
    cells = [3.7] * 15
    mav = dronecan_to_mavlink(BatteryInfo(current=400.0), BatteryInfoAux(voltage_cell=cells), report=report)
    assert mav.current_battery == 32767
    assert mav.voltages == [3700] * 10 and mav.voltages_ext == [3700] * 4
    entries = [e.to_dict() for e in report if e.kind == "clamped"]
    assert {
        "kind": "clamped",
        "field": "mavlink.BATTERY_STATUS.current_battery",
        "detail": "40000.0 outside -32768..32767",
    } in entries
    assert {
        "kind": "clamped",
        "field": "mavlink.BATTERY_STATUS.voltages_ext",
        "detail": "15 cells, room for 10 + 4",
    } in entries


def test_loss_report_names_unknown_targets_and_dropped_sources() -> None:
    report = LossReport()
    uorb_to_mavlink(BatteryStatus(voltage_v=12.0, scale=1.2, priority=2, id=1), report=report)
    dropped = report.fields("dropped")
    assert "uorb.BatteryStatus.scale" in dropped and "uorb.BatteryStatus.priority" in dropped
    unknown = report.fields("unknown")
    assert "mavlink.BATTERY_STATUS.temperature" in unknown and "mavlink.BATTERY_STATUS.mode" in unknown
    assert "mavlink.BATTERY_STATUS.voltages" not in unknown  # the pack voltage went into cell 1


def test_a_known_value_on_the_unknown_marker_is_reported() -> None:
    report = LossReport()
    out = dronecan_to_uorb(BatteryInfo(current=-1.0), report=report)
    assert out.current_a == -1.0
    assert ("clamped", "uorb.BatteryStatus.current_a") in {(e.kind, e.field) for e in report}


def test_no_report_no_cost_and_reports_are_plain_data() -> None:
    out = uorb_to_mavlink(BatteryStatus(voltage_v=80.0))
    assert out.voltages[:2] == [65534, 14466]  # the pack voltage spilled across cells as the spec says
    report = LossReport()
    uorb_to_mavlink(BatteryStatus(), report=report)
    assert all(set(d) <= {"kind", "field", "detail"} for d in report.to_dict())


def test_version_translation_drops_and_zeroes_serial_number() -> None:
    report = LossReport()
    up = uorb_v0_to_uorb(
        BatteryStatusV0(serial_number=1234, voltage_v=11.1, id=2, voltage_cell_v=[3.7] * 3 + [0.0] * 11), report=report
    )
    assert up.voltage_v == 11.1 and up.id == 2 and up.voltage_cell_v[:3] == [3.7] * 3
    assert report.fields("dropped") == ["uorb.BatteryStatusV0.serial_number"]
    down = uorb_to_uorb_v0(up)
    assert down.serial_number == 0 and down.voltage_v == 11.1


# -- devicetree ------------------------------------------------------------------------------


NODE = {
    "compatible": ["simple-battery"],
    "device-chemistry": "lithium-ion",
    "voltage-min-design-microvolt": [[9600000]],
    "voltage-max-design-microvolt": [[12600000]],
    "energy-full-design-microwatt-hours": [52900000],
    "charge-full-design-microamp-hours": [4300000],
    "ocv-capacity-celsius": [-10, 0, 10],
    "ocv-capacity-table-0": [[4185000, 100], [4113000, 95], [4066000, 90]],
    "ocv-capacity-table-1": [[4200000, 100], [4185000, 95], [4113000, 90]],
    "ocv-capacity-table-2": [[4250000, 100], [4200000, 95], [4185000, 90]],
}


def test_devicetree_static_facts_into_uorb_and_dronecan() -> None:
    node = SimpleBattery.from_dict(NODE)
    out = devicetree_to_uorb(node)
    assert out.capacity == 4300 and out.cell_count == 3
    assert out.full_charge_capacity_wh == pytest.approx(52.9) and out.nominal_voltage == pytest.approx(10.8)
    assert out.remaining == -1.0  # no measured voltage given: unknown, not guessed
    info, aux = CONVERTERS[("devicetree", "dronecan")](node, ocv_v=4.15, temperature_c=1)
    assert info.state_of_charge_pct == 92 and aux.nominal_voltage == f16(10.8)


@settings(max_examples=150, deadline=None)
@given(st.integers(4_000_000, 4_300_000), st.integers(-20, 20))
def test_ocv_state_of_charge_agrees_with_the_kernel_model(ocv_uv: int, temp: int) -> None:
    node = SimpleBattery.from_dict(NODE)
    # the kernel's lookup (tests/apps/test_ocv.py checks it against hand-worked values) on the node's tables
    temps = NODE["ocv-capacity-celsius"]
    tables = [NODE[f"ocv-capacity-table-{i}"] for i in range(len(temps))]
    expected = _cells.ocv_to_capacity(tables, temps, ocv_uv, temp)
    out = devicetree_to_uorb(node, ocv_v=ocv_uv / 1e6, temperature_c=temp)
    assert round(out.remaining * 100) == expected


# -- round trips -----------------------------------------------------------------------------

f16s = st.floats(-1000, 1000, allow_nan=False).map(f16)
positive16 = st.floats(0.5, 1000).map(f16)


@settings(max_examples=200, deadline=None)
@given(
    voltage=st.one_of(st.just(NAN), positive16),
    current=st.one_of(st.just(NAN), f16s.filter(lambda x: x != -1.0)),
    temperature=st.one_of(st.just(NAN), st.floats(200, 400).map(f16)),
    soh=st.one_of(st.just(127), st.integers(1, 100)),
    soc=st.one_of(st.just(127), st.integers(0, 100)),
    energies=st.one_of(st.just((NAN, NAN)), st.tuples(positive16, positive16)),
    faults=st.sets(st.sampled_from([8, 16, 32, 64])),
    battery_id=st.integers(0, 254),
    cells=st.lists(st.floats(2.5, 4.4).map(f16), max_size=14),
    counts=st.tuples(st.integers(0, 65535), st.integers(0, 65535)),
    nominal=st.one_of(st.just(0.0), positive16),  # 0 is its unknown (NaN reads as unknown too)
    powering_off=st.booleans(),
)
def test_dronecan_uorb_dronecan_round_trip(
    voltage: float, current: float, temperature: float, soh: int, soc: int, energies: tuple[float, float],
    faults: set[int], battery_id: int, cells: list[float], counts: tuple[int, int], nominal: float, powering_off: bool,
) -> None:  # fmt: skip
    info = BatteryInfo(
        voltage=voltage, current=current, temperature=temperature, state_of_health_pct=soh, state_of_charge_pct=soc,
        remaining_capacity_wh=energies[0], full_charge_capacity_wh=energies[1], status_flags=sum(faults),
        battery_id=battery_id,
    )  # fmt: skip
    aux = BatteryInfoAux(
        voltage_cell=cells, cycle_count=counts[0], over_discharge_count=counts[1], nominal_voltage=nominal,
        is_powering_off=powering_off, battery_id=battery_id,
    )  # fmt: skip
    back, back_aux = uorb_to_dronecan(dronecan_to_uorb(info, aux))
    for name in ("voltage", "current", "temperature", "remaining_capacity_wh", "full_charge_capacity_wh"):
        assert same(getattr(back, name), getattr(info, name)), name
    assert (back.state_of_health_pct, back.battery_id, back.status_flags) == (soh, battery_id, sum(faults))
    if math.isnan(energies[0]):  # with both energies known the hybrid rule derives the percentage from them
        assert back.state_of_charge_pct == (soc or 127)  # 0 % is no estimate (seed 001): written back unknown
    assert back_aux.voltage_cell == cells
    assert (back_aux.cycle_count, back_aux.over_discharge_count) == counts
    assert same(back_aux.nominal_voltage, nominal) and back_aux.is_powering_off == powering_off


def test_known_value_written_as_marker_is_reported() -> None:
    """A current that rounds to MAVLink's -1 cA ("unknown") is written so, and the loss is reported."""
    report = LossReport()
    mav = uorb_to_mavlink(BatteryStatus(current_a=-0.0078125, voltage_v=12.0), report=report)
    assert mav.current_battery == -1
    details = [e.detail for e in report.entries if e.field.endswith("current_battery")]
    assert "a known value written as the unknown marker" in details, details


@settings(max_examples=200, deadline=None)
@given(
    pack=st.one_of(st.just(0.0), st.floats(1.0, 100.0)),
    cells=st.lists(st.floats(2.5, 4.4), min_size=2, max_size=14),
    use_cells=st.booleans(),
    # away from uORB's -1 A marker, and from currents MAVLink's centiamps round to its -1 cA marker (the
    # converter writes those as the marker and reports it: test_known_value_written_as_marker_is_reported)
    current=st.one_of(st.just(-1.0), st.floats(-300, 300).filter(lambda x: abs(x + 1) > 0.01 and abs(x + 0.01) > 5e-3)),
    discharged=st.one_of(st.just(-1.0), st.floats(0, 100_000)),
    remaining=st.one_of(st.just(-1.0), st.floats(0, 1)),
    temperature=st.one_of(st.just(NAN), st.floats(-40, 80)),
    time_remaining=st.one_of(st.just(NAN), st.floats(1, 100_000)),
    warning=st.sampled_from([0, 1, 2, 3, 4, 6, 7]),
    faults=st.integers(0, 255),
    battery_id=st.integers(1, 255),
)
def test_uorb_mavlink_uorb_round_trip(
    pack: float, cells: list[float], use_cells: bool, current: float, discharged: float, remaining: float,
    temperature: float, time_remaining: float, warning: int, faults: int, battery_id: int,
) -> None:  # fmt: skip
    f32 = rt.f32
    status = BatteryStatus(
        voltage_v=f32(pack), current_a=f32(current), discharged_mah=f32(discharged), remaining=f32(remaining),
        temperature=f32(temperature), time_remaining_s=f32(time_remaining), warning=warning, faults=faults,
        id=battery_id,
    )  # fmt: skip
    if use_cells:
        status.cell_count = len(cells)
        status.voltage_cell_v = [f32(c) for c in cells] + [0.0] * (14 - len(cells))
        status.voltage_v = f32(sum(status.voltage_cell_v))
    back = mavlink_to_uorb(uorb_to_mavlink(status))
    tolerances = {"voltage_v": 0.0005 * (len(cells) if use_cells else 1) + 1e-5, "current_a": 0.005 + 1e-5,
                  "discharged_mah": 0.5001, "remaining": 0.005 + 1e-6, "temperature": 0.005 + 1e-4,
                  "time_remaining_s": 0.5001}  # fmt: skip
    for name, tol in tolerances.items():
        a, b = getattr(status, name), getattr(back, name)
        assert same(a, b) or abs(a - b) <= tol * max(1.0, abs(a) * 1e-6 + 1), (name, a, b)
    assert (back.warning, back.faults, back.id) == (warning, faults, battery_id)
    if use_cells:
        assert back.cell_count == len(cells)
        assert all(abs(x - y) <= 0.0005 + 1e-6 for x, y in zip(back.voltage_cell_v, status.voltage_cell_v, strict=True))
    else:
        assert back.voltage_cell_v == [0.0] * 14 and back.cell_count == 0  # sentinels intact


@settings(max_examples=100, deadline=None)
@given(
    voltage=st.one_of(st.just(NAN), st.floats(0.5, 60).map(f16)),
    temperature=st.one_of(st.just(NAN), st.floats(233, 353).map(f16)),
    soc=st.one_of(st.just(127), st.integers(0, 100)),
    battery_id=st.integers(0, 255),
)
def test_dronecan_mavlink_dronecan_round_trip(voltage: float, temperature: float, soc: int, battery_id: int) -> None:
    info = BatteryInfo(voltage=voltage, temperature=temperature, state_of_charge_pct=soc, battery_id=battery_id,
                       current=NAN, remaining_capacity_wh=NAN, full_charge_capacity_wh=NAN)  # fmt: skip
    back, _ = mavlink_to_dronecan(dronecan_to_mavlink(info))
    assert same(back.temperature, temperature)  # cdegC is finer than float16 at these temperatures
    # 0 % is no estimate (seed 001's validity test, 0 < SOC <= 100): it comes back as STATE_OF_CHARGE_UNKNOWN
    assert back.state_of_charge_pct == (soc or 127) and back.battery_id == battery_id
    assert same(back.voltage, voltage) or abs(back.voltage - voltage) <= 0.0005 + abs(voltage) / 2048


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 65535), st.floats(0, 30).map(rt.f32), st.integers(0, 14), st.booleans())
def test_uorb_v0_round_trip(serial: int, voltage: float, cells: int, required: bool) -> None:
    v0 = BatteryStatusV0(serial_number=serial, voltage_v=voltage, cell_count=cells, is_required=required)
    back = uorb_to_uorb_v0(uorb_v0_to_uorb(v0))
    expected = v0.to_dict() | {"serial_number": 0}
    assert all(
        same(a, b) if isinstance(a, float) else a == b
        for a, b in zip(back.to_dict().values(), expected.values(), strict=True)
    )


def test_concepts_are_a_format_too() -> None:
    state = dronecan_to_concepts(BatteryInfo(voltage=12.5, temperature=300.0), BatteryInfoAux(voltage_cell=[4.0] * 3))
    assert isinstance(state, BatteryState)
    assert state.pack_voltage == 12.5 and state.temperature == 300.0 and state.cell_voltages == (4.0, 4.0, 4.0)
    again = BatteryState.from_dict(state.to_dict())
    assert again == state
    info, aux = dronecan_from_concepts(again)
    assert info.voltage == 12.5 and aux.voltage_cell == [4.0] * 3
    with pytest.raises(ConversionError, match="pack_voltage: expected a number"):
        BatteryState.from_dict({"pack_voltage": "high"})


# -- the generator is safe whatever names a schema holds ---------------------------------------


def test_generated_converters_are_valid_and_inert_with_hostile_names(tmp_path: Path, import_generated) -> None:  # type: ignore[no-untyped-def]
    schemas = tmp_path / "schemas"
    (schemas / "uorb").mkdir(parents=True)
    (schemas / "mappings").mkdir()
    (schemas / "uorb" / "Odd.msg").write_text(
        "uint64 timestamp\nfloat32 lambda # [V] [@invalid NaN] the pack\nuint8 class\n"
    )
    (schemas / "mappings" / "m.yaml").write_text(
        "concepts:\n"
        '  pack_voltage: {kind: number, unit: V, doc: "\\"\\"\\" import os; os.system(\'x\') #"}\n'
        "  cell_count: {kind: integer}\n"
        "endpoints:\n"
        "  odd:\n"
        '    doc: "\'\'\'\\"\\"\\""\n'
        "    messages: {import: uorb.Odd}\n"
        "mappings:\n"
        "  - name: odd\n"
        "    source: odd\n"
        "    target: concepts\n"
        "    reversible: true\n"
        '    doc: "\\"\\"\\"; raise SystemExit"\n'
        "    rules:\n"
        "      - {op: scale, from: lambda, to: pack_voltage}\n"
        "      - {op: copy, from: class, to: cell_count, unknown: [0]}\n"
    )
    schema = load([schemas])
    pkg = import_generated(schema, "convert")
    odd_cls = pkg.ENDPOINTS["odd"][0][1]
    state = pkg.CONVERTERS[("odd", "concepts")](odd_cls(lambda_=3.5, class_=4))
    assert (state.pack_voltage, state.cell_count) == (3.5, 4)
    back = pkg.CONVERTERS[("concepts", "odd")](state)
    assert (back.lambda_, back.class_) == (3.5, 4)
    assert ROOT.is_dir()


# -- the generated text is reviewable -------------------------------------------------------------


def test_generated_converters_are_formatted_and_lint_clean() -> None:
    convert = ROOT / "generated" / "convert"
    for args in (["format", "--check"], ["check"]):
        proc = subprocess.run(
            [sys.executable, "-m", "ruff", *args, "--no-force-exclude", str(convert)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=False,
        )
        assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = [
        (p.name, n, line) for p in sorted(convert.glob("*.py")) for n, line in enumerate(p.read_text().splitlines())
    ]
    assert [(name, n) for name, n, line in lines if len(line) > 120] == []
    assert [(name, n) for name, n, line in lines if re.search(r"\b_[KCET]\d+", line)] == []  # constants have names


def test_every_rule_is_preceded_by_its_mapping_file_and_line() -> None:
    schema = load([ROOT / "schemas"])
    for mapping in mappings.all_mappings(schema):
        text = (ROOT / "generated" / "convert" / f"_map_{mapping.name}.py").read_text()
        for rule in mapping.rules:
            assert f"    # {rule.location}: {rule.op.NAME} " in text, rule.location
