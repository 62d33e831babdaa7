"""Our devicetree frontend against dtschema (the reference dt-schema implementation).

(a) dtschema's meta-schema check accepts the battery binding we ship;
(b) every binding shipped inside the dtschema package parses, and each property type we resolve
    is one dtschema's own type extraction (DTValidator.property_get_type) gives it;
(c) each battery.yaml property has dtschema's type, and matrices have dtschema's dimensions;
(d) per-position bounds (``items`` lists, the IR's ArrayType.columns) allow exactly the values
    dtschema's processed schema allows at every position, in battery.yaml and the whole corpus.

dtschema widens every string to string-array when it collects types, so "string" and
"non-unique-string-array" compare as "string-array".
"""

from __future__ import annotations

import itertools
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from codegen.frontends import devicetree as dt
from codegen.ir import ArrayType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Range, Schema
from codegen.text.yaml_lines import load

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


# (d) ----------------------------------------------------------------------------------------


def _positions(t: FieldType, limit: int = 3) -> list[tuple[int, ...]]:
    """Index paths to the numbers of a value: up to ``limit`` per level, within the capacity."""
    dims: list[range] = []
    while isinstance(t, ArrayType):
        dims.append(range(min(t.capacity, limit) if t.capacity is not None else limit))
        t = t.element
    return list(itertools.product(*dims)) if dims else []


def _numeric(t: FieldType) -> bool:
    while isinstance(t, ArrayType):
        t = t.element
    return isinstance(t, PrimitiveType) and t.kind in (PrimitiveKind.INT, PrimitiveKind.UINT)


def _our_range(f: Field, path: tuple[int, ...]) -> Range | None:
    t, rng = f.type, f.range
    for i in path:
        assert isinstance(t, ArrayType)
        if i < len(t.columns) and t.columns[i].range is not None:
            rng = t.columns[i].range.intersect(rng)
        t = t.element
    return rng


def _their_leaf(node: Any, path: tuple[int, ...]) -> dict[str, Any]:
    """The schema dtschema applies at ``path`` (items lists by position, an items mapping to all)."""
    for i in path:
        items = node.get("items") if isinstance(node, dict) else None
        if isinstance(items, list):
            node = items[i] if i < len(items) else {}
        elif isinstance(items, dict):
            node = items
        else:
            return {}
    return node if isinstance(node, dict) else {}


def _allows(leaf: dict[str, Any], v: float) -> bool:
    """dtschema's numeric keywords at one position, applied to a number."""
    checks = [
        "minimum" not in leaf or v >= leaf["minimum"],
        "maximum" not in leaf or v <= leaf["maximum"],
        "exclusiveMinimum" not in leaf or v > leaf["exclusiveMinimum"],
        "exclusiveMaximum" not in leaf or v < leaf["exclusiveMaximum"],
        "const" not in leaf or v == leaf["const"],
        "enum" not in leaf or v in leaf["enum"],
    ]
    return all(checks)


def _in(r: Range | None, v: float) -> bool:
    if r is None:
        return True
    low = r.minimum is None or (v > r.minimum if r.exclusive_minimum else v >= r.minimum)
    return low and (r.maximum is None or (v < r.maximum if r.exclusive_maximum else v <= r.maximum))


def _probes(leaf: dict[str, Any], r: Range | None) -> set[float]:
    edges = [leaf.get(k) for k in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "const")]
    edges += list(leaf.get("enum") or []) + ([r.minimum, r.maximum] if r is not None else [])
    nums = [e for e in edges if isinstance(e, int | float) and not isinstance(e, bool)]
    return {n + d for n in nums for d in (-1, 0, 1)} | {0}  # integer cells: integer probes


def _position_mismatches(messages: tuple[Message, ...], validator: Any) -> tuple[int, list[Any]]:
    """(bounded positions compared, disagreements) between our IR and dtschema's processed schemas."""
    bounded, bad = 0, []
    for m in messages:
        info = m.devicetree
        processed = validator.schemas.get(info.schema_id.rstrip("#")) if info is not None else None
        if processed is None:
            continue
        for f in m.fields:
            node = (processed.get("patternProperties" if f.pattern else "properties") or {}).get(f.name)
            if not isinstance(node, dict) or not _numeric(f.type):
                continue
            for path in _positions(f.type):
                leaf, ours = _their_leaf(node, path), _our_range(f, path)
                enum = leaf.get("enum")
                if isinstance(enum, list) and len(enum) != 1 + max(enum) - min(
                    enum
                ):  # not a Range: the IR keeps it as an annotation
                    assert any(tag.endswith(".enum") for tag, _ in f.annotations), (m.qualified_name, f.name)
                    continue
                bounded += ours is not None
                wrong = [v for v in sorted(_probes(leaf, ours)) if _allows(leaf, v) != _in(ours, v)]
                if wrong:
                    bad.append((m.qualified_name, f.name, path, ours, leaf, wrong))
    return bounded, bad


def test_battery_position_bounds_equal_dtschema(battery_validator: Any) -> None:
    msg = dt.parse_file(BATTERY, root=SCHEMAS).message("devicetree.power.supply.battery")
    bounded, bad = _position_mismatches((msg,), battery_validator)
    assert bad == []
    # the percent column of the OCV tables (3 rows probed) and volt-drop-thresh's one cell
    assert bounded == 4
    table = msg.field("^ocv-capacity-table-[0-9]+$").type
    assert isinstance(table, ArrayType) and isinstance(table.element, ArrayType)
    assert table.element.columns[1].range == Range(maximum=100)


def test_corpus_position_bounds_equal_dtschema(corpus: Schema, core_validator: Any) -> None:
    bounded, bad = _position_mismatches(corpus.messages, core_validator)
    assert bad == []
    assert bounded >= 12  # pci-device reg and interrupts cells, -us maxima...
