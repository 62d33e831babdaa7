"""The mappings frontend: the bundled files load into IR that fits the IR schema, and every kind
of malformed mapping file is a SchemaError naming the file, the line and what was expected."""

from __future__ import annotations

import json
import math
from functools import cache
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.backends.python.converters.function import FunctionBuilder
from codegen.errors import SchemaError
from codegen.frontends import mappings
from codegen.frontends.loader import load
from codegen.ir import CONCEPTS_ENDPOINT, Direction, FieldRef, Schema
from codegen.ir import json_form as irjson
from codegen.ir.mapping_values import ConstantRef, ValuePair
from codegen.ir.mapping_visitor import OpVisitor
from codegen.ir.ops import OPS, Const, EnumMap, PX4Conversion, PX4Convert, PX4Int, Scale


@cache
def bundled() -> Schema:
    return load([ROOT / "schemas"])


def test_bundled_mappings_load_and_fit_the_ir_schema() -> None:
    schema = bundled()
    names = {m.name for m in mappings.all_mappings(schema)}
    assert {"dronecan", "uorb", "mavlink", "devicetree", "uorb_v0_up", "uorb_v0_down"} <= names
    assert {"px4_uavcan_bridge", "px4_mavlink_stream", "px4_mavlink_receiver", "px4_uavcannode"} <= names
    assert irjson.validate_ir_json(irjson.schema_to_json(schema)) == []
    concepts = {c.name: c for c in mappings.concepts(schema)}
    assert concepts["temperature"].unit is not None and concepts["temperature"].unit.symbol == "K"
    assert concepts["faults"].kind == "flags" and "over_current" in concepts["faults"].choices


def test_rules_resolve_to_qualified_fields_and_concepts() -> None:
    dronecan = next(m for m in mappings.all_mappings(bundled()) if m.name == "dronecan")
    first = dronecan.rules[0]
    assert first.sources == (FieldRef("dronecan.uavcan.equipment.power.BatteryInfo", "voltage"),)
    assert first.targets == (FieldRef(CONCEPTS_ENDPOINT, "pack_voltage"),)
    assert first.location is not None and first.location.file == "dronecan.yaml"


def test_every_px4_rule_is_documented() -> None:
    for m in mappings.all_mappings(bundled()):
        if m.policy == "px4":
            undocumented = [
                r.location for r in m.rules if not r.doc and not isinstance(r.op, PX4Int | PX4Convert | Const)
            ]
            assert undocumented == [], m.name


_CONCEPTS = """\
concepts:
  pack_voltage: {kind: number, unit: V}
endpoints:
  uorb:
    messages: {status: uorb.BatteryStatus}
"""


def _parse(tmp_path: Path, text: str) -> Schema:
    (tmp_path / "concepts.yaml").write_text(_CONCEPTS)
    (tmp_path / "m.yaml").write_text(text)
    return mappings.parse_dir(tmp_path, schema=bundled())


def _mapping(rule: str) -> str:
    return f"mappings:\n  - name: t\n    source: uorb\n    target: concepts\n    rules:\n      - {rule}\n"


def _error(tmp_path: Path, text: str) -> SchemaError:
    with pytest.raises(SchemaError) as info:
        _parse(tmp_path, text)
    return info.value


def test_a_minimal_mapping_parses(tmp_path: Path) -> None:
    schema = _parse(tmp_path, _mapping("{op: scale, from: voltage_v, to: pack_voltage}"))
    (m,) = mappings.all_mappings(schema)
    assert m.rules[0].targets == (FieldRef("concepts", "pack_voltage"),)
    assert m.rules[0].location is not None and (m.rules[0].location.file, m.rules[0].location.line) == ("m.yaml", 6)


def test_malformed_yaml_names_file_and_line(tmp_path: Path) -> None:
    err = _error(tmp_path, "mappings:\n  - name: [unclosed\n")
    assert err.file == "m.yaml" and err.line >= 2 and "expected well-formed YAML" in err.message


def test_unknown_op_is_rejected_by_the_json_schema(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: teleport, from: voltage_v, to: pack_voltage}"))
    assert (err.file, err.line) == ("m.yaml", 6)
    assert "expected a valid mapping file" in err.message and "teleport" in err.message


def test_missing_required_key(tmp_path: Path) -> None:
    err = _error(tmp_path, "mappings:\n  - name: t\n    source: uorb\n    rules: []\n")
    assert (err.file, err.line) == ("m.yaml", 2) and "target" in err.message


def test_unknown_field_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: scale, from: voltage_volts, to: pack_voltage}"))
    assert (err.file, err.line) == ("m.yaml", 6)
    assert "expected a field of uorb.BatteryStatus" in err.message and "voltage_volts" in err.message


def test_unknown_concept_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: scale, from: voltage_v, to: pack_voltages}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected a declared concept" in err.message
    assert "pack_voltages" in err.message


def test_unknown_endpoint_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: scale, from: voltage_v, to: pack_voltage}").replace("uorb\n", "px5\n", 1))
    assert (
        (err.file, err.line) == ("m.yaml", 3) and "expected a declared endpoint" in err.message and "px5" in err.message
    )


def test_unknown_message_is_named(tmp_path: Path) -> None:
    (tmp_path / "concepts.yaml").write_text(_CONCEPTS.replace("uorb.BatteryStatus", "uorb.BatteryStatusV9"))
    (tmp_path / "m.yaml").write_text("concepts: {}\n")
    with pytest.raises(SchemaError) as info:
        mappings.parse_dir(tmp_path, schema=bundled())
    err = info.value
    assert (err.file, err.line) == ("concepts.yaml", 5) and "expected a known message" in err.message
    assert "uorb.BatteryStatusV9" in err.message


def test_unknown_constant_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: flag, from: faults, to: pack_voltage, mask: FAULT_ON_FIRE}"))
    assert (
        (err.file, err.line) == ("m.yaml", 6)
        and "FAULT_ON_FIRE" in err.message
        and "expected a constant" in err.message
    )


def test_unknown_unit_is_named(tmp_path: Path) -> None:
    (tmp_path / "concepts.yaml").write_text("concepts:\n  x:\n    kind: number\n    unit: furlongs\n")
    (tmp_path / "m.yaml").write_text("concepts: {}\n")
    with pytest.raises(SchemaError) as info:
        mappings.parse_dir(tmp_path, schema=bundled())
    assert (info.value.file, info.value.line) == ("concepts.yaml", 4) and "expected a known unit" in info.value.message


def test_duplicate_concept_across_files(tmp_path: Path) -> None:
    err = _error(tmp_path, "concepts:\n  pack_voltage: {kind: number, unit: V}\n")
    assert (err.file, err.line) == ("m.yaml", 2) and "declared twice" in err.message


def test_alias_required_on_multi_message_endpoints(tmp_path: Path) -> None:
    text = (
        "endpoints:\n  two:\n    messages: {a: uorb.BatteryStatus, b: uorb.BatteryStatusV0}\n"
        "mappings:\n  - name: t\n    source: two\n    target: concepts\n    rules:\n"
        "      - {op: scale, from: voltage_v, to: pack_voltage}\n"
    )
    err = _error(tmp_path, text)
    assert (err.file, err.line) == ("m.yaml", 9) and "expected ALIAS.FIELD" in err.message


def test_cells_needs_an_array(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: cells, from: voltage_v, to: pack_voltage}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected an array field" in err.message


def test_top_level_must_be_a_mapping(tmp_path: Path) -> None:
    err = _error(tmp_path, "- just\n- a list\n")
    assert (err.file, err.line) == ("m.yaml", 1) and "expected a mapping file" in err.message


# -- typed ops ------------------------------------------------------------------------------------


def test_rules_hold_typed_ops_with_typed_parameters() -> None:
    rules = {
        (r.location.file, r.location.line): r for m in mappings.all_mappings(bundled()) for r in m.rules if r.location
    }
    scale = rules["dronecan.yaml", 12].op
    assert isinstance(scale, Scale) and len(scale.unknown) == 1 and math.isnan(scale.unknown[0])
    stream = rules["px4_mavlink_stream.yaml", 40].op
    assert stream == PX4Convert(PX4Conversion.RAW, guard="connected", finite=True, at_least=1, otherwise=0)
    charge = rules["px4_mavlink_stream.yaml", 49].op
    assert isinstance(charge, EnumMap) and charge.default == ConstantRef("MAV_BATTERY_CHARGE_STATE_UNDEFINED")
    assert charge.map[0] == ValuePair(ConstantRef("WARNING_NONE"), ConstantRef("MAV_BATTERY_CHARGE_STATE_OK"))
    assert rules["dronecan.yaml", 46].only is Direction.FORWARD
    assert hash(charge) == hash(rules["px4_mavlink_stream.yaml", 49].op)  # the IR stays hashable


def test_the_op_list_is_written_once() -> None:
    schema = mappings.mappings_json_schema()
    rule = schema["$defs"]["rule"]
    assert rule["properties"]["op"]["enum"] == list(OPS)
    assert [c["if"]["properties"]["op"]["const"] for c in rule["allOf"]] == list(OPS)
    on_file = json.loads((Path(mappings.__file__).parent / "mappings.schema.json").read_text())["$defs"]["rule"]
    assert on_file["properties"]["op"] == {"type": "string"} and "allOf" not in on_file
    assert set(OPS) == {name.removeprefix("visit_") for name in dir(OpVisitor) if name.startswith("visit_")}
    assert all(hasattr(FunctionBuilder, f"visit_{name}") for name in OPS)


def test_op_parameters_come_from_the_op_classes() -> None:
    then = {
        c["if"]["properties"]["op"]["const"]: c["then"]
        for c in mappings.mappings_json_schema()["$defs"]["rule"]["allOf"]
    }
    assert then["flag"]["required"] == ["mask"]
    assert then["px4_convert"]["properties"]["convert"] == {"enum": ["raw", "units"]}
    assert then["scale"]["properties"]["valid_max"] == {"type": "number"}
    assert then["const"]["properties"]["value"]["anyOf"][1] == {"type": "null"}
    assert then["bits_from"]["properties"]["bits"]["additionalProperties"]["required"] == ["field"]


def test_unknown_parameter_is_rejected(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: scale, from: voltage_v, to: pack_voltage, mask: FAULT_SPIKES}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected a valid mapping file" in err.message
    assert "mask" in err.message


def test_ill_typed_parameter_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: scale, from: voltage_v, to: pack_voltage, valid_max: high}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected a valid mapping file" in err.message
    assert "valid_max" in err.message and "high" in err.message


def test_missing_parameter_is_named(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: flag, from: faults, to: pack_voltage}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "'mask' is a required property" in err.message


def test_reference_count_is_checked(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: soc_hybrid, from: voltage_v, to: pack_voltage}"))
    assert (err.file, err.line) == ("m.yaml", 6)
    assert "expected 2 to 3 reference(s) in 'from' for op 'soc_hybrid', got 1" in err.message


def test_unknown_unit_parameter_is_named(tmp_path: Path) -> None:
    rule = "{op: px4_convert, from: voltage_v, to: pack_voltage, convert: units, source_unit: furlongs}"
    err = _error(tmp_path, _mapping(rule))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected a known unit for 'source_unit'" in err.message


def test_constants_in_any_parameter_are_checked(tmp_path: Path) -> None:
    err = _error(tmp_path, _mapping("{op: const, to: pack_voltage, value: WARNING_ON_FIRE}"))
    assert (err.file, err.line) == ("m.yaml", 6) and "expected a constant" in err.message
    assert "WARNING_ON_FIRE" in err.message


def test_ir_json_writes_parameters_as_the_file_does(tmp_path: Path) -> None:
    rule = "{op: copy, from: id, to: pack_voltage, add: -1, unknown: [0, NaN], only: backward}"
    (m,) = mappings.all_mappings(_parse(tmp_path, _mapping(rule)))
    params = irjson.to_jsonable(m.rules[0])["params"]
    assert params == [
        {"name": "add", "value": -1},
        {"name": "unknown", "value": [0, "NaN"]},
        {"name": "only", "value": "backward"},
    ]
