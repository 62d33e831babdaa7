"""The columnar conversion (the IR's mapping rules over numpy columns) gives what the generated
per-record converters give, concept by concept: on the shared real PX4 logs and on records
hypothesis makes for every battery record format (sentinels, markers, edge values and noise)."""

from __future__ import annotations

import dataclasses
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from per_record import concept_converter, states_to_columns
from shared_data import SHARED, real_logs

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.columnar import NotColumnar, convert_columns
from codegen.apps.battery.readers import read_batches
from codegen.apps.battery.sources import instances_to_columns
from codegen.apps.export.table import concept_array
from codegen.apps.schemas.package import bundled_package, model_class
from codegen.inputs.model import UorbClass
from codegen.inputs.records import Record
from codegen.inputs.ulog.columns import UlogColumns
from codegen.inputs.ulog.records import ulog_items
from codegen.ir import ArrayType, PrimitiveKind, PrimitiveType

# every real ULog of ../shared (real_logs(): a collection error under CI when there are none)
LOGS = sorted(SHARED.rglob("*.ulg")) or real_logs()
CATALOG = bundled_catalog()
PACKAGE = bundled_package()


def _model(qualified: str) -> Any:
    return model_class(PACKAGE, CATALOG.schema.message(qualified))


def assert_same(instances: list[Any], qualified: str) -> None:
    """Columnar and per-record conversions of the same records agree on every concept."""
    source = CATALOG.source(qualified)
    message = CATALOG.schema.message(qualified)
    columnar = convert_columns(CATALOG, source, instances_to_columns(message, instances), len(instances))
    convert = concept_converter(PACKAGE.__name__, source)
    per_record = states_to_columns(CATALOG, [convert(x) for x in instances])
    for concept in CATALOG.concepts:
        a, b = concept_array(columnar[concept.name]), concept_array(per_record[concept.name])
        assert a.equals(b), f"{qualified} -> {concept.name}: columnar {a.to_pylist()} != per-record {b.to_pylist()}"


# -- the shared real logs ----------------------------------------------------------------------------


@pytest.mark.parametrize("log", LOGS, ids=lambda p: p.name)
def test_real_logs_columnar_equals_per_record(log: Path) -> None:
    model = _model("uorb.BatteryStatus")
    assert isinstance(model, UorbClass)
    by_instance: dict[int, list[Any]] = {}
    for item in ulog_items(log, log.name, model):
        if isinstance(item, Record) and item.instance is not None and item.location is not None:
            by_instance.setdefault(int(str(item.location["multi_id"])), []).append(item.instance)
    batches = read_batches(log, log.name, CATALOG)
    assert sorted(int(b.instance[0]) for b in batches) == sorted(by_instance)
    convert = concept_converter(PACKAGE.__name__, CATALOG.source(model.QUALIFIED_NAME))
    for batch in batches:
        records = by_instance[int(batch.instance[0])]
        assert batch.n == len(records)
        columnar = convert_columns(CATALOG, CATALOG.source(batch.message), batch.columns, batch.n)
        per_record = states_to_columns(CATALOG, [convert(x) for x in records])
        for concept in CATALOG.concepts:
            a, b = concept_array(columnar[concept.name]), concept_array(per_record[concept.name])
            assert a.equals(b), f"{log.name} multi_id {batch.instance[0]}: {concept.name} differs"
        # the columns themselves are the records' fields (as the per-record decoder fills them)
        assert_same(records, batch.message)


def _shared_logs() -> list[Path]:
    if not LOGS:
        if os.environ.get("CI"):
            pytest.fail(f"no real ULog under {SHARED}")
        pytest.skip(f"no real ULog under {SHARED}")
    return LOGS


def test_every_layout_is_read_as_columns_as_the_per_record_decoder_reads_it() -> None:
    """On every real ULog of ../shared (PX4 1.8-1.16 layouts): the column path (chunks of 1000
    records) gives, field by field, what the generated per-record decoder gives."""
    model = _model("uorb.BatteryStatus")
    checked = 0
    for log_path in _shared_logs():
        with UlogColumns(log_path, log_path.name, model) as log:
            chunks = list(log.instances(chunk=1000))
            for topic, multi_id in sorted({(c.topic, c.multi_id) for c in chunks}):
                mine = [c for c in chunks if (c.topic, c.multi_id) == (topic, multi_id)]
                oracle = log._decoded(topic, multi_id, mine[0].unfilled)
                assert sum(c.n for c in mine) == oracle.n
                for name, expected in oracle.columns.items():
                    got = np.concatenate([c.columns[name] for c in mine])
                    assert got.shape == expected.shape, f"{log_path.name} {name}"
                    assert np.array_equal(got.astype(np.float64), expected.astype(np.float64), equal_nan=True), (
                        f"{log_path.name} multi_id {multi_id}: {name} differs"
                    )
                    checked += 1
    assert checked


# -- generated records --------------------------------------------------------------------------------

_SPECIAL_FLOATS = (0.0, -1.0, math.nan, math.inf, 1.0, 100.0, 127.0, 0.5, 12.6, -3.25)


def _special(field_type: object, draw: st.DrawFn) -> Any:
    element = field_type.element if isinstance(field_type, ArrayType) else field_type
    if not isinstance(element, PrimitiveType):
        return None
    if element.kind is PrimitiveKind.FLOAT:
        return draw(st.sampled_from(_SPECIAL_FLOATS))
    if element.kind is PrimitiveKind.BOOL:
        return draw(st.booleans())
    lo, hi = element.value_range or (0, 0)
    picks = [v for v in (0, 1, 2, 100, 101, 127, -1, int(hi), int(hi) - 1, int(lo)) if lo <= v <= hi]
    return draw(st.sampled_from(picks))


@st.composite
def records(draw: st.DrawFn, qualified: str, size: int) -> Any:
    """A record decoded from random bytes, then some fields (or array elements) set to the values
    converters single out: sentinels, markers, zero, bounds."""
    cls = _model(qualified)
    message = CATALOG.schema.message(qualified)
    try:
        obj = cls.decode(draw(st.binary(min_size=size, max_size=size)))
    except (ValueError, IndexError) as exc:  # a DroneCAN payload whose array lengths do not fit
        raise AssertionError(f"decode of random bytes failed: {exc}") from exc
    names = {f.metadata.get("name", f.name): f.name for f in dataclasses.fields(obj)}
    for f in message.fields:
        attr = names.get(f.name)
        if attr is None or not draw(st.booleans()):
            continue
        value = getattr(obj, attr)
        if isinstance(value, list):
            if value and not isinstance(value[0], bytes | str):
                for i in draw(st.lists(st.integers(0, len(value) - 1), max_size=len(value))):
                    special = _special(f.type, draw)
                    if special is not None:
                        value[i] = type(value[0])(special) if not isinstance(special, float) else special
        elif isinstance(value, int | float) and not isinstance(value, bool | str | bytes):
            special = _special(f.type, draw)
            if special is not None:
                setattr(obj, attr, special if isinstance(value, float) else int(special))
    return obj


def _size(qualified: str) -> int:
    cls = _model(qualified)
    for attr in ("UORB_SIZE", "MAVLINK_MAX_LENGTH"):
        if hasattr(cls, attr):
            return int(getattr(cls, attr))
    raise AssertionError(qualified)


FIXED_SIZE = ["uorb.BatteryStatus", "mavlink.BATTERY_STATUS"]


@pytest.mark.parametrize("qualified", FIXED_SIZE)
@given(data=st.data())
def test_generated_records_columnar_equals_per_record(qualified: str, data: st.DataObject) -> None:
    batch = data.draw(st.lists(records(qualified, _size(qualified)), min_size=1, max_size=12))
    assert_same(batch, qualified)


@given(data=st.data())
def test_generated_dronecan_records(data: st.DataObject) -> None:
    qualified = "dronecan.uavcan.equipment.power.BatteryInfo"
    cls = _model(qualified)
    info = cls.from_dict(
        {
            "voltage": data.draw(st.sampled_from((math.nan, 0.0, 16.5, -1.0))),
            "current": data.draw(st.sampled_from((math.nan, 3.0, 0.0))),
            "temperature": data.draw(st.sampled_from((math.nan, 0.0, 298.0, -5.0))),
            "remaining_capacity_wh": data.draw(st.sampled_from((math.nan, 0.0, 40.0, 90.0))),
            "full_charge_capacity_wh": data.draw(st.sampled_from((math.nan, 0.0, 80.0))),
            "state_of_charge_pct": data.draw(st.integers(0, 127)),
            "state_of_health_pct": data.draw(st.integers(0, 127)),
            "status_flags": data.draw(st.integers(0, 1023)),
            "battery_id": data.draw(st.integers(0, 255)),
            "model_instance_id": data.draw(st.integers(0, 3)),
            "model_name": data.draw(st.sampled_from(("", "PackX"))),
        }
    )
    assert_same([info], qualified)


@given(data=st.data())
def test_generated_cbat_records(data: st.DataObject) -> None:
    """CUAV CBAT: variable-length cells beside a cell count, negated current, percentages, sentinels."""
    qualified = "dronecan.cuav.equipment.power.CBAT"
    cls = _model(qualified)
    batch = []
    for _ in range(data.draw(st.integers(1, 4))):
        cells = data.draw(st.lists(st.sampled_from((3.7, 0.0, math.nan, 4.2)), max_size=15))
        batch.append(
            cls.from_dict(
                {
                    "voltage": data.draw(st.sampled_from((math.nan, 0.0, 22.2))),
                    "current": data.draw(st.sampled_from((math.nan, -12.5, 3.0))),
                    "temperature": data.draw(st.sampled_from((0.0, 298.0, -5.0))),
                    "voltage_cell": cells,
                    "cell_count": data.draw(st.integers(0, 16)),
                    "state_of_charge": data.draw(st.integers(0, 127)),
                    "full_charge_capacity": data.draw(st.sampled_from((0.0, 16000.0))),
                    "average_time_to_empty": data.draw(st.sampled_from((0, 65535, 30))),
                    "status_flags": data.draw(st.integers(0, 2047)),
                }
            )
        )
    assert_same(batch, qualified)


def test_ops_without_a_columnar_form_are_refused() -> None:
    rule = next(r for m in CATALOG.schema.mappings for mp in m.mappings for r in mp.rules if r.op.NAME == "px4_convert")
    from codegen.apps.battery.columnar import ColumnConverter
    from codegen.ir.mapping_visitor import visit

    converter = ColumnConverter(CATALOG, CATALOG.source("uorb.BatteryStatus"), {}, 0)
    with pytest.raises(NotColumnar, match="px4_convert"):
        visit(rule, converter)
    assert np is not None


# -- synthetic older layouts ------------------------------------------------------------------------

_INT_TYPES = ("int8_t", "uint8_t", "int16_t", "uint16_t", "int32_t", "uint32_t", "int64_t", "uint64_t", "bool")
_FLOAT_TYPES = ("float", "double")


def _record(kind: bytes, body: bytes) -> bytes:
    return len(body).to_bytes(2, "little") + kind + body


@st.composite
def older_layouts(draw: st.DrawFn) -> tuple[str, int]:
    """A battery_status format text PX4 might have logged: some of the class's fields, in another
    order, some under their old name or another compatible type, arrays of other lengths."""
    cls = _model("uorb.BatteryStatus")
    fields = [(f.metadata.get("name", f.name), getattr(cls(), f.name)) for f in dataclasses.fields(cls)]
    chosen = draw(st.lists(st.sampled_from(fields[1:]), unique_by=lambda f: f[0], max_size=12))
    members = ["uint64_t timestamp"]
    for name, default in chosen:
        value = default[0] if isinstance(default, list) else default
        types = _FLOAT_TYPES if isinstance(value, float) else _INT_TYPES
        ctype = draw(st.sampled_from(types))
        size = f"[{draw(st.integers(1, 16))}]" if isinstance(default, list) else ""
        if name == "current_average_a" and draw(st.booleans()):
            name = "average_current_a"  # PX4 before v1.12
        members.append(f"{ctype}{size} {name}")
    sizes = {"int8_t": 1, "uint8_t": 1, "bool": 1, "int16_t": 2, "uint16_t": 2, "int32_t": 4, "uint32_t": 4,
             "float": 4, "int64_t": 8, "uint64_t": 8, "double": 8}  # fmt: skip
    size = sum(
        sizes[m.split()[0].split("[")[0]] * int(m.split()[0].partition("[")[2].rstrip("]") or 1) for m in members
    )
    return "battery_status:" + ";".join(members) + ";", size


def _older_log(fmt: str, payloads: list[bytes]) -> bytes:
    head = b"ULog\x01\x12\x35" + b"\x01" + (1000).to_bytes(8, "little")
    flags = _record(b"B", bytes(40))
    out = head + flags + _record(b"F", fmt.encode()) + _record(b"A", b"\x00\x00\x00battery_status")
    return out + b"".join(_record(b"D", b"\x00\x00" + p) for p in payloads)


@settings(max_examples=40, deadline=None)
@given(layout=older_layouts(), data=st.data())
def test_synthetic_older_layouts_as_the_per_record_decoder(layout: tuple[str, int], data: st.DataObject) -> None:
    fmt, size = layout
    payloads = data.draw(st.lists(st.binary(min_size=size, max_size=size), min_size=1, max_size=6))
    model = _model("uorb.BatteryStatus")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "older.ulg"
        path.write_bytes(_older_log(fmt, payloads))
        with UlogColumns(path, path.name, model) as log:
            chunks = list(log.instances(chunk=4))
            assert sum(c.n for c in chunks) == len(payloads)
            oracle = log._decoded("battery_status", 0, chunks[0].unfilled)
            for name, expected in oracle.columns.items():
                got = np.concatenate([c.columns[name] for c in chunks])
                assert got.shape == expected.shape, name
                assert np.array_equal(got.astype(np.float64), expected.astype(np.float64), equal_nan=True), (
                    f"{fmt}: {name}: columns {got.tolist()} != decoder {expected.tolist()}"
                )
