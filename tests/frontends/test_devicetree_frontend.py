"""Devicetree (dt-schema YAML) frontend: error paths and the shipped battery binding."""

from __future__ import annotations

import textwrap
from dataclasses import replace
from pathlib import Path

import pytest

from codegen.errors import SchemaError
from codegen.frontends import devicetree as dt
from codegen.frontends.devicetree.data import PACKAGED, load_data
from codegen.ir import (
    ArrayType,
    Column,
    CompositeType,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    StringType,
    units,
)

SCHEMAS = Path(__file__).resolve().parents[2] / "schemas" / "devicetree"
BATTERY = SCHEMAS / "power" / "supply" / "battery.yaml"

HEAD = """\
$id: http://devicetree.org/schemas/test/thing.yaml#
$schema: http://devicetree.org/meta-schemas/core.yaml#
title: Thing
"""


def _write(tmp_path: Path, text: str, name: str = "thing.yaml") -> Path:
    path = tmp_path / "test" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def _error(tmp_path: Path, text: str) -> SchemaError:
    path = _write(tmp_path, text)
    with pytest.raises(SchemaError) as info:
        dt.parse_file(path, root=tmp_path)
    assert info.value.file == "test/thing.yaml"
    return info.value


def _parse(tmp_path: Path, text: str) -> Message:
    return dt.parse_file(_write(tmp_path, text), root=tmp_path).message("devicetree.test.thing")


# ---------------------------------------------------------------------------------------------
# error paths: each names file, line and what was expected


def test_bad_yaml_reports_line(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo: [1, 2\n  bar: {}\n")
    assert err.line in (5, 6) and "expected well-formed YAML" in err.message


def test_duplicate_key_reports_its_line(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo: true\n  foo: true\n")
    assert (err.line, "duplicate key 'foo'" in err.message) == (6, True)


def test_not_a_mapping(tmp_path: Path) -> None:
    err = _error(tmp_path, "- just\n- a list\n")
    assert err.line == 1 and "expected a mapping" in err.message


def test_missing_id(tmp_path: Path) -> None:
    err = _error(tmp_path, "# comment\ntitle: Thing\nproperties:\n  foo: true\n")
    assert err.line == 2 and "expected a '$id' key" in err.message


def test_id_not_naming_a_yaml_schema(tmp_path: Path) -> None:
    err = _error(tmp_path, "title: x\n$id: http://devicetree.org/schemas/thing\nproperties: {}\n")
    assert err.line == 2 and "expected $id to name a .yaml schema" in err.message


def test_properties_not_a_mapping(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  - foo\n  - bar\n")
    assert err.line == 4 and "expected 'properties' to be a mapping" in err.message


def test_property_schema_not_a_mapping(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo: true\n  bar: 3\n")
    assert err.line == 6 and "expected the schema of 'bar' to be a mapping or true" in err.message


def test_malformed_ref(tmp_path: Path) -> None:
    text = HEAD + "properties:\n  foo:\n    description: x\n    $ref: types.yaml#definitions/uint32\n"
    err = _error(tmp_path, text)
    assert err.line == 7 and "expected $ref to be a URI reference" in err.message


def test_ref_not_a_string(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo:\n    $ref: [1]\n")
    assert err.line == 6 and "expected $ref to be a URI reference" in err.message


def test_unknown_types_definition(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo:\n    $ref: /schemas/types.yaml#/definitions/uint33\n")
    assert err.line == 6 and "expected a types.yaml definition" in err.message and "'uint33'" in err.message


def test_local_ref_pointing_nowhere(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo:\n    $ref: '#/$defs/missing'\n")
    assert err.line == 6 and "to point into this file" in err.message


def test_required_not_strings(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "properties:\n  foo: true\nrequired:\n  - foo\n  - {bar: 1}\n")
    assert err.line == 6 and "expected 'required' to be a list of strings" in err.message


def test_bad_pattern_property(tmp_path: Path) -> None:
    err = _error(tmp_path, HEAD + "patternProperties:\n  '^foo-[0-9+$':\n    type: boolean\n")
    assert err.line == 5 and "regular expression" in err.message


def test_undecodable_file(tmp_path: Path) -> None:
    path = _write(tmp_path, HEAD)
    path.write_bytes(HEAD.encode() + b"title: \xff\n")
    with pytest.raises(SchemaError) as info:
        dt.parse_file(path, root=tmp_path)
    assert (info.value.file, info.value.line) == ("test/thing.yaml", 4)
    assert "expected UTF-8" in info.value.message


# ---------------------------------------------------------------------------------------------
# the battery binding


@pytest.fixture(scope="module")
def battery() -> Message:
    schema = dt.parse_dir(SCHEMAS)
    assert schema.sources == ("power/supply/battery.yaml",)  # data files skipped
    return schema.message("devicetree.power.supply.battery")


def test_battery_message(battery: Message) -> None:
    assert battery.name == "battery"
    assert str(battery.location) == "power/supply/battery.yaml:3"
    assert battery.doc.startswith("Fixed facts about a battery (design voltages, capacity, charging limits,")
    info = battery.devicetree
    assert info is not None
    assert info.schema_id == "http://devicetree.org/schemas/power/supply/battery.yaml#"
    assert info.title == "Battery Characteristics"
    assert info.compatible == ("simple-battery",)
    assert info.required == ("compatible",)
    assert info.additional_properties is False
    assert info.maintainers == ("Sebastian Reichel <sre@kernel.org>",)
    assert [f.name for f in battery.fields if f.required] == ["compatible"]


def test_battery_units_from_suffixes(battery: Message) -> None:
    f = battery.field("voltage-min-design-microvolt")
    assert f.unit == units.lookup("uV") and f.unit_text == "microvolt"
    assert f.location.line == 54
    expected = {
        "charge-full-design-microamp-hours": "uAh",
        "energy-full-design-microwatt-hours": "uWh",
        "factory-internal-resistance-micro-ohms": "uOhm",
        "operating-range-celsius": "degC",
        "volt-drop-temperatures-millicelsius": "mdegC",
        "volt-drop-soc-bp": "bp",
        "^volt-drop-[0-9]-microvolt": "uV",
    }
    for name, symbol in expected.items():
        unit = battery.field(name).unit
        assert unit is not None and unit.symbol == symbol, name
    assert battery.field("resistance-temp-table").unit is None


def test_battery_types(battery: Message) -> None:
    i32, u32 = PrimitiveType(PrimitiveKind.INT, 32), PrimitiveType(PrimitiveKind.UINT, 32)
    # -microvolt is an int32-matrix in dt-schema; a bare number is a 1x1 matrix
    open_row = ArrayType(i32, None, dynamic=True, min_length=1)
    assert battery.field("voltage-max-design-microvolt").type == ArrayType(open_row, None, True, 1)
    one = ArrayType(i32, 1, dynamic=False, min_length=1)
    thresh = battery.field("volt-drop-thresh-microvolt")
    assert thresh.type == ArrayType(one, 1, False, 1) and thresh.range == Range(maximum=48000000)
    assert battery.field("precharge-current-microamp").type == ArrayType(u32, None, True, 1)
    alert = battery.field("alert-celsius").type
    assert isinstance(alert, ArrayType) and replace(alert, columns=()) == ArrayType(i32, 2, False, 2)
    assert [c.doc for c in alert.columns] == [
        "alert below this battery temperature",
        "alert above this battery temperature",
    ]
    chem = battery.field("device-chemistry")
    assert chem.type == StringType() and chem.choices[:2] == ("nickel-cadmium", "nickel-metal-hydride")
    assert len(chem.choices) == 6 and ("choice.lithium-ion" in dict(chem.annotations))
    compat = battery.field("compatible")
    assert compat.type == ArrayType(StringType(), None, True, 1) and compat.const == "simple-battery"


def test_battery_ocv_table_pattern_field(battery: Message) -> None:
    f = battery.field("^ocv-capacity-table-[0-9]+$")
    assert f.pattern == f.name and not f.required and f.location.line == 146
    where = "power/supply/battery.yaml"
    columns = (
        Column("open-circuit voltage in microvolts", location=Location(where, 155)),
        Column("state of charge in percent", range=Range(maximum=100), location=Location(where, 156)),
    )
    row = ArrayType(PrimitiveType(PrimitiveKind.UINT, 32), 2, dynamic=False, min_length=2, columns=columns)
    assert f.type == ArrayType(row, 100, dynamic=True, min_length=1)  # the columns sit on the row type
    notes = dict(f.annotations)
    assert notes == {"dt-type": "uint32-matrix", "dt-type-source": "ref"}  # nothing left over
    assert f.range is None  # only the percent column is bounded
    assert "[1]" not in f.doc and f.doc.startswith("Rows of (open-circuit voltage, charge percent)")


def test_battery_columns_of_arrays(battery: Message) -> None:
    t = battery.field("operating-range-celsius").type
    assert isinstance(t, ArrayType) and [c.doc for c in t.columns] == [
        "lowest usable temperature",
        "highest usable temperature",
    ]
    assert all(c.range is None and c.unit is None for c in t.columns)
    table = battery.field("resistance-temp-table").type
    assert isinstance(table, ArrayType) and isinstance(table.element, ArrayType) and table.columns == ()
    assert [c.doc for c in table.element.columns] == [
        "temperature in degrees Celsius",
        "internal resistance in percent of the factory value",
    ]


def test_items_lists_become_columns_at_any_depth(tmp_path: Path) -> None:
    msg = _parse(
        tmp_path,
        HEAD
        + textwrap.dedent(
            """        properties:
          pair:
            $ref: /schemas/types.yaml#/definitions/uint32-array
            items:
              - description: low
                minimum: 2
              - const: 7
              - enum: [1, 2, 3]
              - enum: [1, 5]
              - {}
          table:
            $ref: /schemas/types.yaml#/definitions/int32-matrix
            maxItems: 4
            items:
              items:
                - description: a
                  exclusiveMinimum: -5
                  maximum: 5
                - description: b
          one-row:
            $ref: /schemas/types.yaml#/definitions/uint32-matrix
            items:
              - description: the row
                items:
                  - minimum: 1
                  - maximum: 9
          two-rows:
            $ref: /schemas/types.yaml#/definitions/uint32-matrix
            items:
              - items: [{maximum: 1}]
              - items: [{maximum: 2}]
          flat-microvolt:
            items:
              - description: min
              - description: max
                maximum: 5000000
        """
        ),
    )
    pair = msg.field("pair")
    assert isinstance(pair.type, ArrayType)
    assert [(c.doc, c.range) for c in pair.type.columns] == [
        ("low", Range(minimum=2)),
        ("", Range(7, 7)),
        ("", Range(1, 3)),  # an enum without gaps is a range; one with gaps is not: kept as a note
    ]  # the trailing positions say nothing the IR holds and are left out
    assert pair.type.columns[0].location == Location("test/thing.yaml", 8)
    assert dict(pair.annotations)["item[3].enum"] == "[1, 5]"
    table = msg.field("table").type
    assert isinstance(table, ArrayType) and isinstance(table.element, ArrayType)
    assert [(c.doc, c.range) for c in table.element.columns] == [
        ("a", Range(-5, 5, exclusive_minimum=True)),
        ("b", None),
    ]
    one = msg.field("one-row").type
    assert isinstance(one, ArrayType) and isinstance(one.element, ArrayType)
    assert [c.doc for c in one.columns] == ["the row"] and (one.min_length, one.capacity) == (1, 1)
    assert [c.range for c in one.element.columns] == [Range(minimum=1), Range(maximum=9)]
    two = msg.field("two-rows")
    assert isinstance(two.type, ArrayType) and isinstance(two.type.element, ArrayType)
    assert two.type.element.columns == ()  # rows that differ cannot share one row type
    assert dict(two.annotations)["row[1].column[0].maximum"] == "2"
    flat = msg.field("flat-microvolt").type  # a -microvolt list written flat is one row
    assert isinstance(flat, ArrayType) and isinstance(flat.element, ArrayType) and flat.columns == ()
    assert [(c.doc, c.range) for c in flat.element.columns] == [("min", None), ("max", Range(maximum=5000000))]


def test_battery_parse_is_deterministic(battery: Message) -> None:
    again = dt.parse_file(BATTERY, root=SCHEMAS).message("devicetree.power.supply.battery")
    assert again == battery


# ---------------------------------------------------------------------------------------------
# data files and other constructs


def test_packaged_data_matches_schema_root() -> None:
    for name in ("types.yaml", "property-units.yaml"):
        assert (PACKAGED / name).read_bytes() == (SCHEMAS / name).read_bytes()


def test_unit_rules_agree_with_unit_registry() -> None:
    data = load_data(SCHEMAS)
    for suffix, symbol in units.DT_SUFFIX_UNITS:
        rule = data.unit_rule("x" + suffix)
        assert rule is not None and rule.unit.symbol == symbol, suffix
        assert units.devicetree_suffix_unit("x" + suffix) == rule.unit
    assert data.unit_rule("opp-hz") is not None and data.unit_rule("opp-hz").type == "uint64-matrix"  # type: ignore[union-attr]
    assert data.unit_rule("ti,x-plate-ohms") is None


def test_flags_phandles_nodes_and_unknowns(tmp_path: Path) -> None:
    msg = _parse(
        tmp_path,
        HEAD
        + textwrap.dedent(
            """\
        properties:
          enable-thing:
            type: boolean
          other-flag:
            $ref: types.yaml#/definitions/flag
          monitored-battery: true
          vendor,blob:
            description: nothing says what this is
          level:
            allOf:
              - $ref: /schemas/types.yaml#/definitions/uint32
              - enum: [1, 2, 3]
          child:
            type: object
            properties:
              reg:
                maxItems: 1
          port:
            $ref: /schemas/graph.yaml#
          cluster:
            $ref: '#/$defs/cluster'
        $defs:
          cluster:
            type: object
            patternProperties:
              '^cluster[0-9]+$':
                $ref: '#/$defs/cluster'
        unevaluatedProperties: false
        if:
          properties:
            compatible:
              const: x
        then:
          required: [level]
        """
        ),
    )
    assert msg.field("enable-thing").type == PrimitiveType(PrimitiveKind.BOOL, 1)
    assert msg.field("other-flag").type == PrimitiveType(PrimitiveKind.BOOL, 1)
    phandle = msg.field("monitored-battery")
    assert phandle.type == PrimitiveType(PrimitiveKind.UINT, 32) and "dt-phandle" in dict(phandle.annotations)
    blob = msg.field("vendor,blob")
    assert isinstance(blob.type, ArrayType) and dict(blob.annotations)["dt-type"] == "unknown"
    level = msg.field("level")
    assert level.type == PrimitiveType(PrimitiveKind.UINT, 32) and level.choices == (1, 2, 3)
    assert msg.field("child").type == CompositeType("devicetree.test.thing.child")
    assert msg.field("port").type == CompositeType("devicetree.graph")
    assert msg.field("cluster").type == CompositeType("devicetree.test.thing.cluster")
    assert msg.devicetree is not None and msg.devicetree.additional_properties is False
    schema = dt.parse_file(tmp_path / "test" / "thing.yaml", root=tmp_path)
    names = [m.qualified_name for m in schema.messages]
    assert names == ["devicetree.test.thing", "devicetree.test.thing.child", "devicetree.test.thing.cluster"]
    cluster = schema.message("devicetree.test.thing.cluster")
    assert cluster.fields[0].type == CompositeType("devicetree.test.thing.cluster")  # recursion kept, no loop
