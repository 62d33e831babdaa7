"""The mappings frontend: the bundled files load into IR that fits the IR schema, and every kind
of malformed mapping file is a SchemaError naming the file, the line and what was expected."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.errors import SchemaError
from codegen.frontends import mappings
from codegen.frontends.loader import load
from codegen.ir import CONCEPTS_ENDPOINT, FieldRef, Schema
from codegen.ir import json_form as irjson
from codegen.ir.ops import Const, PX4Convert, PX4Int


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
