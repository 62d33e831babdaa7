"""Differential test: jsonschema's Draft 2020-12 validator on our JSON Schema export and the
generated ``from_dict`` + ``validate()`` agree on random valid and invalid plain-JSON instances of
every bundled message.

Per-position constraints (ArrayType.columns, exported as prefixItems) are drawn on and beyond
their bounds too, so the OCV tables' percent column is compared cell by cell.

Out of the comparison, as documented in codegen/backends/json_schema.py: cross-field rules
(not exported) and warnings (never make an instance invalid). Instances are JSON data: NaN and the
infinities appear as the strings the export documents; a bool is never written 1.0, and byte-array
text and text with a byte capacity (MAVLink char arrays) are ASCII (where the JSON data model cannot
tell what the reader tells: maxLength counts characters, the capacity UTF-8 bytes).
"""

from __future__ import annotations

import importlib
import math
import re
import string
from pathlib import Path
from typing import Any

import hypothesis.strategies as st
import jsonschema
import pytest
from hypothesis import HealthCheck, given, settings

from codegen.backends.json_schema import at_column, export_all
from codegen.backends.python import naming
from codegen.backends.python.validators.bounds import enum_facts, folded
from codegen.frontends.loader import load
from codegen.ir import (
    FLOAT_MAX,
    ArrayType,
    CompositeType,
    Field,
    FieldType,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
)
from codegen.ir import StringType as StrT

ROOT = Path(__file__).resolve().parent.parent
SCHEMA = load([ROOT / "schemas"])
EXPORT = export_all(SCHEMA)
MESSAGES = [m.qualified_name for m in SCHEMA.messages]
_meta = importlib.import_module("generated._meta")
JUNK = st.sampled_from(["x", None, [], {}, "NaN", "Infinity", True])


def model(msg: Message) -> Any:
    return getattr(importlib.import_module("generated." + naming.module_path(msg)), naming.class_name(msg))


def ours_valid(msg: Message, data: dict[str, Any]) -> tuple[bool, object]:
    try:
        obj = model(msg).from_dict(data)
    except _meta.DataError as exc:
        return False, exc
    found = [v for v in obj.validate() if v.severity == "error" and not v.rule.startswith("cross-field:")]
    return not found, found


# --------------------------------------------------------------------------------------------
# Strategies drawn from the IR: values inside, on and beyond every bound the schema states.


def _number(schema: Schema, f: Field, t: PrimitiveType) -> st.SearchStrategy[Any]:
    if t.kind is PrimitiveKind.BOOL:
        return st.sampled_from([True, False, 0, 1, 2, -1, 0.5, "true", None])
    b = folded(t, f.range)
    edges: list[Any] = [b.low, b.high]
    if t.kind is PrimitiveKind.FLOAT:
        top = FLOAT_MAX[t.bits]
        edges += [top, -top, top * 1.001, -top * 1.001, 65504.0, 65505.0, 1e39, "NaN", "nan", "Infinity", "-inf"]
        edges += [b.low - 0.5, b.high + 0.5] if math.isfinite(b.low) and abs(b.low) < 1e30 else []
        core: st.SearchStrategy[Any] = st.floats(-1e6, 1e6) | st.integers(-1000, 1000)
    else:
        edges += [b.low - 1, b.high + 1, 2.0, 2.5, "3"]
        facts = enum_facts(schema, f)
        if facts is not None and facts.values is not None:
            edges += [v + d for v in facts.values for d in (0, 1)]
        if facts is not None and facts.mask is not None:
            edges += [facts.mask, facts.mask + 1, *facts.bits, *(1 << i for i in range(t.bits + 1))]
        core = st.integers(int(max(b.low, -(2**40))) - 2, int(min(b.high, 2**40)) + 2)
    if f.invalid is not None:
        edges.append("NaN" if f.invalid.is_nan else f.invalid.value)
    edges = [e for e in edges if not (isinstance(e, float) and math.isinf(e))]
    return st.one_of(core, st.sampled_from(edges), JUNK)


def _value(schema: Schema, f: Field, t: FieldType, depth: int = 0) -> st.SearchStrategy[Any]:
    if isinstance(t, PrimitiveType):
        return _number(schema, f, t)
    if isinstance(t, StrT):
        known = [str(c) for c in f.choices] + ([f.const] if isinstance(f.const, str) else [])
        if t.capacity is not None:  # a capacity counts UTF-8 bytes, JSON Schema's maxLength characters
            text = st.text(alphabet=string.printable, max_size=t.capacity + 2)
            return st.sampled_from([*known, "", "other"]) | text | JUNK
        return st.sampled_from([*known, "", "other"]) | st.text(max_size=4) | JUNK
    if isinstance(t, CompositeType):
        return _object(schema, schema.message(t.name), depth + 1)
    el = t.element
    inner = _value(schema, f, el, depth + 1)
    cap = t.capacity
    sizes: list[st.SearchStrategy[Any]] = [st.lists(inner, max_size=3)]
    if cap is not None:
        fill = st.sampled_from([0, 1, 100]) if isinstance(el, PrimitiveType) else inner
        sizes += [st.lists(fill, min_size=cap, max_size=cap), st.lists(fill, min_size=cap + 1, max_size=cap + 1)]
        if cap <= 16:
            sizes.append(st.lists(inner, min_size=max(cap - 1, 0), max_size=cap))
    if t.columns:  # each position drawn around its own column's bounds, then maybe one more element
        heads = _column_cells(schema, f, t, depth)
        sizes += [heads, st.builds(lambda h, rest: [*h, *rest], heads, st.lists(inner, max_size=1))]
    if isinstance(el, ArrayType) and el.columns:  # a table whose every row is drawn by its columns
        sizes.append(st.lists(_column_cells(schema, f, el, depth + 1), min_size=1, max_size=3))
    if isinstance(el, PrimitiveType) and el.kind is PrimitiveKind.UINT and el.bits == 8:
        sizes.append(st.text(alphabet=string.printable, max_size=(cap or 8) + 2))
    return st.one_of(*sizes, JUNK)


def _column_cells(schema: Schema, f: Field, t: ArrayType, depth: int) -> st.SearchStrategy[list[Any]]:
    """One value per column, around that column's bounds; numbers only, so the row reaches validate()."""
    cells = [_value(schema, at_column(f, c), t.element, depth + 1) for c in t.columns]
    if isinstance(t.element, PrimitiveType):
        cells = [c.filter(lambda v: isinstance(v, int | float) and not isinstance(v, bool)) for c in cells]
    return st.tuples(*cells).map(list)


SAMPLE_NAMES = ("ocv-capacity-table-0", "ocv-capacity-table-17", "volt-drop-3-microvolt")  # for pattern fields


def _column_fields(schema: Schema, msg: Message) -> dict[str, st.SearchStrategy[Any]]:
    """The fields with columns, each drawn position by position (tables row by row)."""
    out: dict[str, st.SearchStrategy[Any]] = {}
    for f in msg.fields:
        t = f.type
        if isinstance(t, ArrayType) and isinstance(t.element, ArrayType) and t.element.columns:
            value = st.lists(_column_cells(schema, f, t.element, 1), min_size=1, max_size=3)
        elif isinstance(t, ArrayType) and t.columns:
            value = _column_cells(schema, f, t, 0)
        else:
            continue
        for name in [n for n in SAMPLE_NAMES if _match(f.pattern, n)] if f.pattern else [f.name]:
            out[name] = value
    return out


def _strategies(schema: Schema, msg: Message, depth: int) -> dict[str, st.SearchStrategy[Any]]:
    out: dict[str, st.SearchStrategy[Any]] = {}
    for f in msg.fields:
        if f.is_padding:
            continue
        if f.pattern is not None:
            for name in SAMPLE_NAMES:
                if _match(f.pattern, name):
                    out[name] = _value(schema, f, f.type, depth)
            continue
        out[f.name] = _value(schema, f, f.type, depth)
    return out


def _match(pattern: str, name: str) -> bool:
    return re.search(pattern, name) is not None


def _object(schema: Schema, msg: Message, depth: int = 0) -> st.SearchStrategy[dict[str, Any]]:
    """A few fields (changes over a valid base, or a whole instance of a nested message)."""
    fields = _strategies(schema, msg, depth)
    fields["not-a-field"] = st.just(1)
    names = sorted(fields)
    return st.lists(st.sampled_from(names), max_size=3 if depth == 0 else len(names), unique=True).flatmap(
        lambda keys: st.fixed_dictionaries({k: fields[k] for k in keys})
    )


# what a valid instance needs beyond the defaults
VALID_BASE: dict[str, dict[str, Any]] = {
    "uorb.BatteryStatus": {"max_error": 1},
    "uorb.BatteryStatusV0": {"max_error": 1},
    "devicetree.power.supply.battery": {"compatible": ["simple-battery"]},
    "mavlink.PARAM_VALUE": {"param_type": 9},  # MAV_PARAM_TYPE has no 0
}


# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", MESSAGES)
def test_export_is_a_valid_draft_2020_12_schema(name: str) -> None:
    jsonschema.Draft202012Validator.check_schema(EXPORT[name])


@pytest.mark.parametrize("name", MESSAGES)
def test_jsonschema_and_generated_validator_agree(name: str) -> None:
    msg = SCHEMA.message(name)
    validator = jsonschema.Draft202012Validator(EXPORT[name])
    outcomes = {True: 0, False: 0}
    base_data = {**model(msg)().to_dict(), **VALID_BASE.get(name, {})}
    assert validator.is_valid(base_data) and ours_valid(msg, base_data)[0]

    columns = _column_paths(msg)
    column_verdicts = 0  # instances both sides refused over a column's own bound

    def compare(data: dict[str, Any]) -> None:
        nonlocal column_verdicts
        expected = validator.is_valid(data)
        got, detail = ours_valid(msg, data)
        if not got and isinstance(detail, list) and any(_column_violation(v.path, columns) for v in detail):
            column_verdicts += 1
        assert got == expected, (
            f"{name}: jsonschema says {'valid' if expected else 'invalid'}, the generated validator "
            f"says {'valid' if got else 'invalid'} for {data!r}: "
            f"{[e.message for e in validator.iter_errors(data)]} / {detail}"
        )
        outcomes[got] += 1

    @settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck), database=None)
    @given(_object(SCHEMA, msg), st.booleans())
    def run(data: dict[str, Any], over_defaults: bool) -> None:
        # a valid instance with a few fields changed, or those fields alone (the rest defaulted)
        compare({**base_data, **data} if over_defaults else data)

    run()
    compare(base_data)
    assert outcomes[True] > 0 and outcomes[False] > 0, f"{name}: only one verdict drawn: {outcomes}"
    if not columns:
        return
    fields = _column_fields(SCHEMA, msg)

    @settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
    @given(st.fixed_dictionaries({}, optional=fields))
    def around_columns(data: dict[str, Any]) -> None:
        compare({**base_data, **data})

    around_columns()
    assert column_verdicts > 0, f"{name}: no instance broke a column bound ({columns})"


def _column_paths(msg: Message) -> list[tuple[str, int]]:
    """(field name or pattern, nesting depth) of every array level with a bounded column."""
    out = []
    for f in msg.fields:
        t, depth = f.type, 0
        while isinstance(t, ArrayType):
            if any(c.range is not None for c in t.columns):
                out.append((f.pattern or f.name, depth))
            t, depth = t.element, depth + 1
    return out


def _column_violation(path: str, columns: list[tuple[str, int]]) -> bool:
    """A range violation at a bounded column (``ocv-capacity-table-0[3][1]``)."""
    name, _, rest = path.partition("[")
    indexes = [int(i) for i in re.findall(r"\[(\d+)\]", "[" + rest)] if rest else []
    return any(
        (re.search(key, name) if key.startswith("^") else key == name) and len(indexes) == depth + 1
        for key, depth in columns
    )


def test_column_bounds_agree() -> None:
    """The OCV tables' percent column: 100 is fine, 101 is not, in both the export and validate()."""
    battery = SCHEMA.message("devicetree.power.supply.battery")
    v = jsonschema.Draft202012Validator(EXPORT[battery.qualified_name])
    base = VALID_BASE[battery.qualified_name]
    for cell, valid in ((100, True), (0, True), (101, False), (4294967295, False), (-1, False)):
        data = {**base, "ocv-capacity-table-0": [[4200000, 100], [3700000, cell]]}
        assert v.is_valid(data) is valid, cell
        got, found = ours_valid(battery, data)
        assert got is valid, (cell, found)
        if not valid and cell == 101:
            assert isinstance(found, list) and [x.path for x in found] == ["ocv-capacity-table-0[1][1]"]
            assert found[0].message.endswith("state of charge in percent = 101 is above the maximum 100")
    errors = list(v.iter_errors({**base, "ocv-capacity-table-3": [[4200000, 101]]}))
    assert [list(e.absolute_path) for e in errors] == [["ocv-capacity-table-3", 0, 1]]


def test_sentinels_and_nan_spelling_agree() -> None:
    """The decisions the export documents, on fixed instances."""
    status = SCHEMA.message("uorb.BatteryStatus")
    v = jsonschema.Draft202012Validator(EXPORT["uorb.BatteryStatus"])
    base = {"max_error": 1}
    cases = [
        ({"remaining": -1}, True),  # the sentinel, outside the range 0..1
        ({"remaining": 1.5}, False),
        ({"temperature": "NaN"}, True),  # NaN is temperature's "unknown"
        ({"voltage_v": "NaN"}, False),  # no NaN sentinel here
        ({"voltage_v": "Infinity"}, False),
        ({"faults": 1 << 10}, True),
        ({"faults": 1 << 11}, False),
        ({"voltage_cell_v": [0.0] * 15}, False),
        ({"warning": 5}, False),
        ({}, False),  # max_error defaults to 0, outside 1..100: required in the export
    ]
    for change, valid in cases:
        data = {**base, **change} if change else {}
        assert v.is_valid(data) is valid, change
        assert ours_valid(status, data)[0] is valid, change
    info = jsonschema.Draft202012Validator(EXPORT["dronecan.uavcan.equipment.power.BatteryInfo"])
    assert not info.is_valid({"status_flags": 0x200})  # STATUS_FLAG_RESERVED_A must be zero
    assert info.is_valid({"state_of_health_pct": 127})
    assert not info.is_valid({"temperature": 65505.0})
