"""Generated validators: every rule of the contract on the bundled messages, the wording, and the
fast path never passing a value the careful diagnosis would report."""

from __future__ import annotations

import dataclasses
import importlib
import math
from pathlib import Path
from typing import Any

import hypothesis.strategies as st
import pytest
from hypothesis import given, settings

from codegen.backends.python.naming import upper_snake
from codegen.ir import (
    ArrayType,
    Column,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
    StringType,
)
from generated._validate import ValidationError, Violation, diag
from generated.devicetree import SimpleBattery
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo
from generated.mavlink import BatteryStatus as MavBatteryStatus
from generated.uorb import BatteryStatus

ROOT = Path(__file__).resolve().parents[2]


def _rules_of(found: list[Violation]) -> list[tuple[str, str]]:
    return [(v.path, v.rule) for v in found]


def _status(**kw: Any) -> BatteryStatus:
    return BatteryStatus(max_error=1, **kw)


# --------------------------------------------------------------------------------------------
# uORB


def test_valid_defaults_and_sentinels() -> None:
    s = _status()
    assert s.validate() == []
    assert not s.is_known("remaining") and not s.is_known("temperature") and not s.is_known("voltage_cell_v")
    assert s.is_known("timestamp")
    s.remaining, s.temperature = 0.5, 21.0
    s.voltage_cell_v[0] = 4.1
    assert s.is_known("remaining") and s.is_known("temperature") and s.is_known("voltage_cell_v")
    with pytest.raises(KeyError, match=r"'nope' is not a field of uorb\.BatteryStatus"):
        s.is_known("nope")


def test_range_wording_with_units() -> None:
    found = _status(remaining=1.5).validate()
    assert found == [Violation("remaining", "range", 1.5, 1, "remaining = 1.5 is above the maximum 1")]
    found = _status(cell_count=3, voltage_cell_v=[4.0, 4.0, 4.0] + [0.0] * 11, scale=0.5).validate()
    assert found[0].message == "scale = 0.5 is below the minimum 1"
    s = _status(cell_count=4, voltage_cell_v=[4.0, 4.0, 4.0, 5e39] + [0.0] * 10)
    (v,) = s.validate()
    assert (v.path, v.rule) == ("voltage_cell_v[3]", "type-bounds")
    assert v.limit == (-3.4028234663852886e38, 3.4028234663852886e38)
    assert v.message == "voltage_cell_v[3] = 5e+39 V is beyond the float32 limit ±3.40282347e+38 V (it would saturate)"


def test_nan_and_infinity() -> None:
    assert _status(temperature=math.nan, time_remaining_s=math.nan).validate() == []
    found = _status(voltage_v=math.nan, current_a=math.inf, remaining=-math.inf).validate()
    assert _rules_of(found) == [("voltage_v", "nan"), ("current_a", "type-bounds"), ("remaining", "type-bounds")]
    assert found[0].message == "voltage_v is NaN, which is not allowed here (its 'unknown' value is 0)"
    assert found[1].message == "current_a = inf is not a finite number"
    found = _status(voltage_cell_v=[math.nan] + [0.0] * 13).validate()
    assert _rules_of(found) == [("voltage_cell_v[0]", "nan")]


def test_enums_and_bit_indices() -> None:
    assert _status(warning=7, source=2, faults=(1 << 11) - 1).validate() == []
    found = _status(warning=5, source=3, faults=1 << 11).validate()
    assert _rules_of(found) == [("source", "enum"), ("warning", "enum"), ("faults", "bitmask")]
    assert found[1].message.startswith("warning = 5 is not one of WARNING_NONE (0), WARNING_LOW (1)")
    assert found[2].message == "faults = 0x800 sets undefined or reserved bits 0x800; only 0x7ff may be set"


def test_wrong_python_types_are_reported_not_raised() -> None:
    s = _status()
    s.voltage_v = "12"  # type: ignore[assignment]
    s.cell_count = 2.5  # type: ignore[assignment]
    s.voltage_cell_v = "x" * 14  # type: ignore[assignment]
    found = s.validate()
    assert _rules_of(found)[:2] == [("voltage_v", "type"), ("cell_count", "type")]
    assert found[0].message == "voltage_v = '12' is not a number (float32)"
    assert ("voltage_cell_v", "type") in _rules_of(found)


def test_array_length() -> None:
    s = _status(voltage_cell_v=[0.0] * 15)
    assert s.validate() == [
        Violation("voltage_cell_v", "length", 15, 14, "voltage_cell_v has 15 items, it must have exactly 14")
    ]


def test_cell_count_rules() -> None:
    found = _status(cell_count=15).validate()
    assert _rules_of(found) == [("cell_count", "cross-field:cell-count-capacity")]
    found = _status(cell_count=2, voltage_cell_v=[4.0, 4.0, 3.9] + [0.0] * 11).validate()
    assert _rules_of(found) == [("voltage_cell_v[2]", "cross-field:cells-beyond-count-zero")]
    assert found[0].message == "voltage_cell_v[2] = 3.9 V but the battery has only 2 cells; expected 0"
    # cell_count unknown (0): nothing to say about the cells
    assert _status(cell_count=0, voltage_cell_v=[4.0] * 3 + [0.0] * 11).validate() == []


def test_check_raises_with_every_violation() -> None:
    s = _status(remaining=2.0, warning=9)
    with pytest.raises(ValidationError) as info:
        s.check()
    assert isinstance(info.value, ValueError)
    assert [v.path for v in info.value.violations] == ["remaining", "warning"]
    assert str(info.value).startswith("uorb.BatteryStatus: 2 violations: remaining = 2 is above the maximum 1")
    _status().check()


# --------------------------------------------------------------------------------------------
# DroneCAN, MAVLink


def test_dronecan_widths_reserved_bits_and_nested_paths() -> None:
    info = BatteryInfo(state_of_health_pct=127, state_of_charge_pct=100, status_flags=0x1FF)
    assert info.validate() == [] and not info.is_known("state_of_health_pct")
    found = BatteryInfo(state_of_charge_pct=128, temperature=65505.0, status_flags=0x400).validate()
    assert _rules_of(found) == [
        ("temperature", "type-bounds"),
        ("status_flags", "bitmask"),
        ("state_of_charge_pct", "type-bounds"),
        ("state_of_charge_pct", "cross-field:state-of-charge-percent"),
    ]
    assert found[0].message == "temperature = 65505 K is beyond the float16 limit ±65504 K (it would saturate)"
    assert "STATUS_FLAG_RESERVED_B" in found[1].message
    assert found[2].message == "state_of_charge_pct = 128 % does not fit uint7 (0..127)"
    assert _rules_of(BatteryInfo(state_of_health_pct=101).validate()) == [
        ("state_of_health_pct", "cross-field:state-of-health-percent")
    ]
    aux = BatteryInfoAux(voltage_cell=[4.0] * 256)
    aux.timestamp.usec = 1 << 56
    found = aux.validate()
    assert _rules_of(found) == [("timestamp.usec", "type-bounds"), ("voltage_cell", "length")]
    assert found[0].message.startswith("timestamp.usec = 72057594037927936 us does not fit uint56")


def test_mavlink_per_element_sentinel() -> None:
    m = MavBatteryStatus()
    assert m.validate() == [] and not m.is_known("voltages") and not m.is_known("temperature")
    m.voltages = [4000] + [65535] * 9
    assert m.is_known("voltages") and m.validate() == []
    m.voltages[3], m.temperature, m.battery_remaining = 70000, -32769, 101
    assert _rules_of(m.validate()) == [
        ("temperature", "type-bounds"),
        ("voltages[3]", "type-bounds"),
        ("battery_remaining", "cross-field:battery-remaining-percent"),
    ]


# --------------------------------------------------------------------------------------------
# Devicetree

EXAMPLE = {
    "compatible": ["simple-battery"],
    "over-voltage-threshold-microvolt": [[4500000]],
    "re-charge-voltage-microvolt": [[250000]],
    "voltage-min-design-microvolt": [[3200000]],
    "voltage-max-design-microvolt": [[4200000]],
    "energy-full-design-microwatt-hours": [5290000],
    "charge-full-design-microamp-hours": [1430000],
    "precharge-current-microamp": [256000],
    "precharge-upper-limit-microvolt": [[2500000]],
    "charge-term-current-microamp": [128000],
    "constant-charge-current-max-microamp": [900000],
    "constant-charge-voltage-max-microvolt": [[4200000]],
    "factory-internal-resistance-micro-ohms": [250000],
    "ocv-capacity-celsius": [-10, 0, 10],
    "ocv-capacity-table-0": [[4185000, 100], [4113000, 95], [4066000, 90]],
    "ocv-capacity-table-1": [[4200000, 100], [4185000, 95], [4113000, 90]],
    "ocv-capacity-table-2": [[4250000, 100], [4200000, 95], [4185000, 90]],
    "resistance-temp-table": [[20, 100], [10, 90], [0, 80], [4294967286, 60]],
    "operating-range-celsius": [-30, 50],
    "ambient-celsius": [-5, 50],
    "alert-celsius": [0, 40],
}


def test_binding_example_is_valid() -> None:
    node = SimpleBattery.from_dict(EXAMPLE)
    assert node.validate() == []
    assert node.is_known("ocv-capacity-celsius") and not node.is_known("device-chemistry")


def test_devicetree_structure() -> None:
    node = SimpleBattery.from_dict(EXAMPLE)
    node.compatible = None  # type: ignore[assignment]
    node.device_chemistry = "lead-acid"
    node.volt_drop_thresh_microvolt = [[48000001]]
    node.voltage_min_design_microvolt = [[1 << 31]]
    node.ocv_capacity_table_n["ocv-table-9"] = [[1, 2]]
    found = [v for v in node.validate() if not v.rule.startswith("cross-field:")]
    assert _rules_of(found) == [
        ("compatible", "required"),
        ("device-chemistry", "enum"),
        ("voltage-min-design-microvolt[0][0]", "type-bounds"),
        ("volt-drop-thresh-microvolt[0][0]", "range"),
        ("ocv-table-9", "pattern"),
    ]
    assert found[0].message == "compatible is required but missing"
    assert found[3].message == "volt-drop-thresh-microvolt[0][0] = 48000001 uV is above the maximum 48000000 uV"
    node = SimpleBattery.from_dict({**EXAMPLE, "compatible": ["other-battery"]})
    assert _rules_of(node.validate()) == [("compatible[0]", "enum")]


def test_devicetree_cross_field_rules() -> None:
    data = {
        **EXAMPLE,
        "voltage-min-design-microvolt": [[4300000]],
        "constant-charge-voltage-max-microvolt": [[4600000]],
        "ocv-capacity-table-1": [[4100000, 100], [4185000, 101]],
    }
    del data["ocv-capacity-table-2"]
    found = SimpleBattery.from_dict(data).validate()
    assert [(v.path, v.rule, v.severity) for v in found] == [
        ("ocv-capacity-table-1[1][1]", "range", "error"),  # the binding's own column maximum, not a rule
        ("voltage-min-design-microvolt", "cross-field:voltage-design-order", "error"),
        ("constant-charge-voltage-max-microvolt", "cross-field:charge-voltage-below-over-voltage", "error"),
        ("voltage-max-design-microvolt", "cross-field:design-max-below-charge-voltage", "warning"),
        ("ocv-capacity-table-1[1]", "cross-field:ocv-table-descending", "error"),
        ("ocv-capacity-celsius", "cross-field:ocv-table-count", "error"),
        ("ocv-capacity-celsius[2]", "cross-field:ocv-table-names", "error"),
    ]
    assert found[1].message == (
        "voltage-min-design-microvolt = 4300000 uV must be below voltage-max-design-microvolt = 4200000 uV"
    )
    # advice alone does not fail check()
    SimpleBattery.from_dict({**EXAMPLE, "voltage-max-design-microvolt": [[4100000]]}).check()


def test_devicetree_columns_name_what_the_position_holds() -> None:
    table = [[4185000, 100], [4113000, 95], [4066000, 90], [4000000, 101]]
    found = SimpleBattery.from_dict({**EXAMPLE, "ocv-capacity-table-0": table}).validate()
    assert found == [
        Violation(
            "ocv-capacity-table-0[3][1]",
            "range",
            101,
            100,
            "ocv-capacity-table-0[3][1]: state of charge in percent = 101 is above the maximum 100",
        )
    ]
    # the OCV column has no bound beyond uint32; a wrong type there is named by its column too
    table[3] = [-1, 50]
    node = SimpleBattery.from_dict(EXAMPLE)
    node.ocv_capacity_table_n["ocv-capacity-table-0"] = table
    (v,) = node.validate()
    assert v.path == "ocv-capacity-table-0[3][0]" and v.rule == "type-bounds"
    assert v.message.startswith("ocv-capacity-table-0[3][0]: open-circuit voltage in microvolts = -1 does not fit")
    node = SimpleBattery.from_dict(EXAMPLE)
    node.operating_range_celsius = [-30, 1 << 31]
    (v,) = node.validate()
    assert v.message.startswith("operating-range-celsius[1]: highest usable temperature = ")
    assert SimpleBattery.from_dict({**EXAMPLE, "ocv-capacity-table-2": [[3000000, 100], [2900000, 0]]}).validate() == []


# --------------------------------------------------------------------------------------------
# Generic paths on a made-up schema: exclusive bounds, signed sentinels, UTF-8 capacity, inf ranges

LOC = Location("x.msg", 1)
I16 = PrimitiveType(PrimitiveKind.INT, 16)
F64 = PrimitiveType(PrimitiveKind.FLOAT, 64)


def _made_up() -> Schema:
    flags = EnumDef("uorb.X.FLAG", EnumKind.BITMASK, (EnumEntry("FLAG_A", 1), EnumEntry("FLAG_C", 4)))
    fields = (
        Field("t", I16, LOC, range=Range(-100, 100, True, True), invalid=Sentinel(-32768, "INT16_MIN")),
        Field("g", F64, LOC, range=Range(0, math.inf)),
        Field("name", StringType(4), LOC),
        Field("flags", PrimitiveType(PrimitiveKind.UINT, 8), LOC, enums=("uorb.X.FLAG",)),
        Field("m", ArrayType(ArrayType(I16, 2, False), 3, True, 1), LOC),
    )
    return Schema(messages=(Message("X", "uorb.X", SourceFormat.UORB, LOC, "", fields, enums=(flags,)),))


def test_made_up_schema(import_generated: Any) -> None:
    X = import_generated(_made_up(), "uorb").X
    ok = X(t=99, g=math.inf, name="ab€"[:2], flags=5, m=[[1, 2]])
    assert ok.validate() == []
    assert X(t=-32768, m=[[0, 0]]).validate() == [] and not X(t=-32768).is_known("t")
    found = X(t=100, g=-1.0, name="ab€", flags=2, m=[]).validate()
    expected = [("t", "range"), ("g", "range"), ("name", "length"), ("flags", "bitmask"), ("m", "length")]
    assert _rules_of(found) == expected
    assert found[0].message == "t = 100 is at or above the exclusive maximum 100"
    assert found[2].message == "name is 5 bytes of UTF-8, more than its 4"
    assert _rules_of(X(m=[[1, 2, 3], [40000, 0]]).validate()) == [("m[0]", "length"), ("m[1][0]", "type-bounds")]


def _with_columns() -> Schema:
    u8 = PrimitiveType(PrimitiveKind.UINT, 8)
    row = ArrayType(I16, 2, False, columns=(Column(), Column("pct", range=Range(maximum=100))))
    pair = (Column("low", range=Range(-10, 10)), Column(), Column("third", range=Range(0, 5, True)))
    cell = Sentinel(-99.0, "-99", per_element=True)
    fields = (
        # dynamic, nothing guarantees position 2 exists: the fast path guards it
        Field("pair", ArrayType(I16, 4, True, columns=pair), LOC),
        Field("head", ArrayType(u8, 4, False, columns=(Column("version", range=Range(1, 3)),)), LOC),
        Field("rows", ArrayType(row, None, True), LOC),
        # the column narrows the field's own range; the sentinel stays valid everywhere
        Field(
            "f",
            ArrayType(F64, 3, False, columns=(Column("x", range=Range(0, 1)),)),
            LOC,
            range=Range(-5, 5),
            invalid=cell,
        ),
    )
    return Schema(messages=(Message("C", "uorb.C", SourceFormat.UORB, LOC, "", fields),))


def test_columns_on_a_made_up_schema(import_generated: Any) -> None:
    C = import_generated(_with_columns(), "uorb").C
    ok = C(pair=[-10, 99, 5], head=b"\x03abc", rows=[[-5, 100], [7, 0]], f=[-99.0, -5.0, 5.0])
    assert ok.validate() == []
    found = C(pair=[11, 99, 0], head=b"\x00abc", rows=[[0, 0], [0, 101]], f=[1.5, 6.0, 0.0]).validate()
    assert _rules_of(found) == [
        ("pair[0]", "range"),
        ("pair[2]", "range"),
        ("head[0]", "range"),
        ("rows[1][1]", "range"),
        ("f[0]", "range"),
        ("f[1]", "range"),
    ]
    assert found[1].message == "pair[2]: third = 0 is at or below the exclusive minimum 0"
    assert found[2].message == "head[0]: version = 0 is below the minimum 1"
    assert found[4].message == "f[0]: x = 1.5 is above the maximum 1"
    assert found[5].message == "f[1] = 6 is above the maximum 5"
    assert C(pair=[3], head=b"\x01abc", rows=[[]]).validate()[0].path == "rows[0]"  # length, not rows[0][1]
    assert C(pair=[3], head=b"\x01abc").validate() == []  # a short dynamic array: its missing positions pass

    module = importlib.import_module(C.__module__)
    specs = {f.name: getattr(module, f"_C_{upper_snake(f.name)}_SPEC") for f in dataclasses.fields(C)}
    their_diag = module._v.diag  # the generated package's own runtime, not generated/_validate.py
    cells = st.one_of(st.integers(-20, 120), st.sampled_from([0, 5, 6, 100, 101, -99.0, 1.5, 40000, "x", None]))

    @settings(max_examples=300, deadline=None, database=None)
    @given(
        st.lists(cells, max_size=5),
        st.binary(max_size=5) | st.lists(cells, max_size=5),
        st.lists(st.lists(cells, max_size=3) | cells, max_size=3),
        st.lists(cells | st.floats(-7, 7), max_size=4),
    )
    def run(pair: Any, head: Any, rows: Any, f: Any) -> None:
        obj = C(pair=pair, head=head, rows=rows, f=f)
        careful: list[Any] = []
        for fl in dataclasses.fields(C):
            their_diag(careful, fl.metadata["name"], getattr(obj, fl.name), specs[fl.name])
        assert obj.validate() == careful

    run()


# --------------------------------------------------------------------------------------------
# The fast path never passes what diag reports


def _specs(cls: type) -> dict[str, Any]:
    module = importlib.import_module(cls.__module__)
    prefix = upper_snake(cls.__name__)
    return {f.name: getattr(module, f"_{prefix}_{upper_snake(f.name)}_SPEC") for f in dataclasses.fields(cls)}


VALUES = st.one_of(
    st.integers(-(2**65), 2**65),
    st.sampled_from([0, 1, -1, 127, 128, 255, 256, 65535, 65536, 2047, 2048, 0x200, 100, 101, True, False]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([65504.0, 65505.0, 3.4028234663852886e38, 3.5e38, -0.0, 1.0, 0.5, 2.0]),
    st.text(max_size=2),
    st.none(),
)


@pytest.mark.parametrize("cls", [BatteryStatus, BatteryInfo, MavBatteryStatus, BatteryInfoAux, SimpleBattery])
def test_fast_path_agrees_with_diagnosis(cls: type) -> None:
    specs = _specs(cls)
    names = sorted(specs)

    @settings(max_examples=150, deadline=None, database=None)
    @given(st.dictionaries(st.sampled_from(names), VALUES, max_size=4), st.data())
    def run(changes: dict[str, Any], data: st.DataObject) -> None:
        obj = cls()
        for name, value in changes.items():
            current = getattr(obj, name)
            if isinstance(current, list):
                value = [*current[:-1], value]
            setattr(obj, name, value)
        careful: list[Violation] = []
        for f in dataclasses.fields(cls):
            meta_name = f.metadata["name"]
            diag(careful, meta_name, getattr(obj, f.name), specs[f.name])
        fast = [v for v in obj.validate() if not v.rule.startswith("cross-field:")]
        assert fast == careful

    run()


def test_fast_path_agrees_on_devicetree_tables() -> None:
    """OCV tables and two-cell ranges around their column bounds (the generic draw above leaves
    devicetree lists unset)."""
    specs = _specs(SimpleBattery)
    cell = st.one_of(st.integers(-2, 102), st.sampled_from([4200000, 1 << 32, -(1 << 31) - 1, 100.0, 1.5, "x", None]))
    row = st.lists(cell, min_size=1, max_size=3) | cell
    tables = st.dictionaries(
        st.sampled_from(["ocv-capacity-table-0", "ocv-capacity-table-12", "nope"]),
        st.lists(row, max_size=4) | cell,
        max_size=2,
    )

    @settings(max_examples=200, deadline=None, database=None)
    @given(tables, st.none() | st.lists(cell, max_size=3), st.none() | st.lists(row, max_size=3))
    def run(table: dict[str, Any], span: Any, resistance: Any) -> None:
        obj = SimpleBattery.from_dict(EXAMPLE)
        obj.ocv_capacity_table_n = table
        obj.operating_range_celsius, obj.resistance_temp_table = span, resistance
        careful: list[Violation] = []
        for f in dataclasses.fields(SimpleBattery):
            diag(careful, f.metadata["name"], getattr(obj, f.name), specs[f.name])
        assert [v for v in obj.validate() if not v.rule.startswith("cross-field:")] == careful

    run()
