"""Our devicetree frontend against dtschema (the reference dt-schema implementation).

(a) dtschema's meta-schema check accepts the battery binding we ship;
(b) every binding shipped inside the dtschema package parses, and each property type we resolve
    is one dtschema's own type extraction (DTValidator.property_get_type) gives it;
(c) each battery.yaml property has dtschema's type, and matrices have dtschema's dimensions.

dtschema widens every string to string-array when it collects types, so "string" and
"non-unique-string-array" compare as "string-array".
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from codegen.frontends import devicetree as dt
from codegen.frontends.devicetree_yaml import load
from codegen.ir import ArrayType, Field, Schema

dtschema = pytest.importorskip("dtschema")

SCHEMAS = Path(__file__).resolve().parent.parent / "schemas" / "devicetree"
BATTERY = SCHEMAS / "power" / "supply" / "battery.yaml"
DTSCHEMA_ROOT = Path(dtschema.__file__).resolve().parent / "schemas"
DOC_VALIDATE = Path(sys.executable).parent / "dt-doc-validate"


def _norm(dt_type: str) -> str:
    return "string-array" if dt_type in ("string", "non-unique-string-array") else dt_type


def _ours(f: Field) -> str:
    return dict(f.annotations)["dt-type"]


def _theirs(validator: Any, f: Field) -> set[str]:
    """dtschema's types for a field: a pattern property's own entry, else name matching."""
    if f.pattern is not None:
        entry = validator.pat_props.get(f.name)
        if entry and entry[0]["type"]:
            return {_norm(entry[0]["type"])}
    return {_norm(t) for t in validator.property_get_type(f.name)} - {"node"}


def _dims(t: Any) -> tuple[tuple[int, int], tuple[int, int]]:
    """Our matrix shape in dtschema's notation: ((min rows, max rows), (min, max per row)); 0 = open."""
    assert isinstance(t, ArrayType) and isinstance(t.element, ArrayType)
    return ((t.min_length, t.capacity or 0), (t.element.min_length, t.element.capacity or 0))


# (a) ----------------------------------------------------------------------------------------


def test_dt_doc_validate_cli_accepts_battery() -> None:
    for args in ([str(BATTERY)], ["-u", str(SCHEMAS), str(BATTERY)]):
        done = subprocess.run([str(DOC_VALIDATE), *args], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        assert done.stderr.strip() == ""


def test_dtschema_meta_schema_api_accepts_battery() -> None:
    sch = dtschema.DTSchema(str(BATTERY))
    assert list(sch.iter_errors()) == []
    assert sch["$id"] == "http://devicetree.org/schemas/power/supply/battery.yaml#"


# (b) ----------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def corpus() -> Schema:
    return dt.parse_dir(DTSCHEMA_ROOT)


@pytest.fixture(scope="module")
def core_validator() -> Any:
    return dtschema.DTValidator([])


def test_every_dtschema_binding_parses(corpus: Schema) -> None:
    files = sorted(DTSCHEMA_ROOT.rglob("*.yaml"))
    bindings = [
        p.relative_to(DTSCHEMA_ROOT).as_posix()
        for p in files
        if p.name not in ("types.yaml", "property-units.yaml") and dt.is_binding(load(p.read_text("utf-8"), p.name))
    ]
    assert len(bindings) >= 50
    assert list(corpus.sources) == bindings
    names = [m.qualified_name for m in corpus.messages]
    assert names == sorted(names) and len(set(names)) == len(names)
    for source in corpus.sources:  # one top-level message per file, named after its $id
        assert any(
            m.location.file == source
            and m.devicetree
            and m.devicetree.schema_id.endswith(source.removesuffix(".yaml") + ".yaml#")
            for m in corpus.messages
        ), source


def test_property_types_agree_with_dtschema(corpus: Schema, core_validator: Any) -> None:
    compared, unresolved, disagree = 0, [], []
    for m in corpus.messages:
        for f in m.fields:
            ours, theirs = _ours(f), _theirs(core_validator, f)
            if ours == "node" or not theirs:
                continue
            if ours == "unknown":
                unresolved.append((m.qualified_name, f.name))
                continue
            compared += 1
            if _norm(ours) not in theirs:
                disagree.append((m.qualified_name, f.name, ours, sorted(theirs)))
    assert disagree == []
    assert compared >= 250
    # properties dtschema types through other schemas we do not follow: at most a few
    assert len(unresolved) <= compared // 20, unresolved


# (c) ----------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def battery_validator() -> Any:
    return dtschema.DTValidator([str(BATTERY)])


def test_battery_types_equal_dtschema(battery_validator: Any) -> None:
    msg = dt.parse_file(BATTERY, root=SCHEMAS).message("devicetree.power.supply.battery")
    assert len(msg.fields) == 26
    for f in msg.fields:
        theirs = _theirs(battery_validator, f)
        assert theirs == {_norm(_ours(f))}, f.name


def test_battery_matrix_dimensions_equal_dtschema(battery_validator: Any) -> None:
    msg = dt.parse_file(BATTERY, root=SCHEMAS).message("devicetree.power.supply.battery")
    checked = 0
    for f in msg.fields:
        if f.pattern is not None:
            entry = battery_validator.pat_props.get(f.name)
            theirs = entry[0].get("dim") if entry else None
        else:
            theirs = battery_validator.property_get_type_dim(f.name)
        if theirs is None:
            continue
        assert _dims(f.type) == tuple(tuple(d) for d in theirs), f.name
        checked += 1
    assert checked == 3  # resistance-temp-table, volt-drop-thresh-microvolt, ^ocv-capacity-table-[0-9]+$
