"""The fleet table as Arrow: one schema for every log, concept columns in SI units, unknown as null.

Columns: the context of each record (``log``, ``source``, ``vehicle``, ``battery``, ``t``,
``time``, ``message``), then one column per shared concept in the order concepts.yaml lists them.
Each concept column's field metadata holds its ``unit`` and ``quantity`` (from the IR's unit
registry), its ``kind``, its doc, and ``source_fields``: per source message, the fields it is
read from (JSON), so a reader of the Parquet files knows what each value means without battgen.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa

from .catalog import Catalog
from .columns import ConceptColumn, NDArray
from .sources import Batch

_ARROW_TYPES: dict[str, Any] = {
    "number": pa.float64(),
    "integer": pa.int64(),
    "bool": pa.bool_(),
    "text": pa.string(),
    "choice": pa.string(),
    "flags": pa.list_(pa.string()),
    "list": pa.list_(pa.float64()),
}

# the context of every record: (name, Arrow type, doc, unit)
CONTEXT: tuple[tuple[str, Any, str, str | None], ...] = (
    ("log", pa.string(), "stable id of the log's content (sha256 of the file, first 16 hex digits)", None),
    ("source", pa.string(), "file name of the log", None),
    ("vehicle", pa.string(), "the vehicle, where the log says (ULog sys_uuid or hardware, MAVLink system id)", None),
    ("battery", pa.int32(), "battery instance (the concept battery_index where known, else the log's instance)", None),
    ("t", pa.float64(), "seconds since the log's start", "s"),
    ("time", pa.timestamp("us", tz="UTC"), "time of day (UTC), where the log has it", None),
    ("armed", pa.bool_(), "whether the vehicle was armed, where the log says (ULog actuator_armed)", None),
    ("message", pa.string(), "the source message (qualified name) the record was decoded as", None),
)


def battery_schema(catalog: Catalog) -> Any:
    """The Arrow schema of the battery table (the same for every log and format)."""
    fields = []
    for name, typ, doc, unit in CONTEXT:
        meta = {"doc": doc}
        if unit:
            meta |= {"unit": unit, "quantity": "time"}
        fields.append(pa.field(name, typ, nullable=name not in ("log", "source", "message"), metadata=meta))
    for concept in catalog.concepts:
        meta = {"kind": concept.kind, "doc": concept.doc}
        if concept.unit is not None:
            meta |= {"unit": concept.unit.symbol, "quantity": concept.unit.quantity}
        if concept.choices:
            meta["choices"] = json.dumps(list(concept.choices))
        sources = {q: list(s.sources_of(concept.name)) for q, s in sorted(catalog.sources.items())}
        meta["source_fields"] = json.dumps({q: f for q, f in sources.items() if f}, sort_keys=True)
        fields.append(pa.field(concept.name, _ARROW_TYPES[concept.kind], metadata=meta))
    return pa.schema(fields, metadata={"battgen": json.dumps({"table": "battery", "version": 1})})


def concept_array(col: ConceptColumn) -> Any:
    """One concept column as an Arrow array: unknown (and NaN) as null."""
    kind = col.concept.kind
    if not col.valid.any():  # a concept the source never gives: no arrays to build
        return pa.nulls(len(col.valid), _ARROW_TYPES[kind])
    invalid = ~col.valid
    if kind == "number":
        return pa.array(col.values, type=pa.float64(), mask=invalid | np.isnan(col.values))
    if kind in ("integer", "bool"):
        return pa.array(col.values, type=_ARROW_TYPES[kind], mask=invalid)
    if kind == "text":
        return pa.array(col.values, type=pa.string(), mask=invalid)
    choices = pa.array(list(col.concept.choices), type=pa.string())
    if kind == "choice":
        codes = pa.array(col.values.astype(np.int32), mask=invalid)
        return pa.DictionaryArray.from_arrays(codes, choices).cast(pa.string())
    if kind == "flags":
        bits = ((col.values[:, None] >> np.arange(len(col.concept.choices))) & 1).astype(bool)
        bits &= col.valid[:, None]
        return _lists(bits, pa.DictionaryArray.from_arrays(np.asarray(np.nonzero(bits)[1], np.int32), choices), invalid)
    assert col.lengths is not None
    used = (np.arange(col.values.shape[1]) < col.lengths[:, None]) & col.valid[:, None]
    flat = col.values[used]
    return _lists(used, pa.array(flat, type=pa.float64(), mask=np.isnan(flat)), invalid)


def _lists(used: NDArray, values: Any, invalid: NDArray) -> Any:
    offsets = np.zeros(used.shape[0] + 1, np.int32)
    np.cumsum(used.sum(axis=1), out=offsets[1:])
    if isinstance(values, pa.DictionaryArray):
        values = values.cast(pa.string())
    return pa.ListArray.from_arrays(pa.array(offsets), values, mask=pa.array(invalid))


def battery_table(
    catalog: Catalog, schema: Any, columns: Mapping[str, ConceptColumn], batch: Batch, log: str, source: str
) -> Any:
    """The battery table of one batch of records of the log ``log`` (its content id), file ``source``."""
    n = batch.n
    index = columns["battery_index"]
    battery = np.asarray(np.where(index.valid, index.values, batch.instance), np.int32)
    timestamp = pa.timestamp("us", tz="UTC")
    arrays: list[Any] = [
        pa.repeat(pa.scalar(log, pa.string()), n),
        pa.repeat(pa.scalar(source, pa.string()), n),
        pa.nulls(n, pa.string())
        if batch.vehicle is None
        else pa.repeat(pa.scalar(batch.vehicle, pa.string()), n)
        if isinstance(batch.vehicle, str)
        else pa.array(batch.vehicle, type=pa.string()),
        pa.array(battery, type=pa.int32()),
        pa.array(batch.t, type=pa.float64(), mask=np.isnan(batch.t)),
        pa.nulls(n, timestamp) if batch.time_us is None else pa.array(batch.time_us, type=pa.int64()).cast(timestamp),
        pa.nulls(n, pa.bool_())
        if batch.armed is None
        else pa.array(batch.armed == 1.0, type=pa.bool_(), mask=np.isnan(batch.armed)),
        pa.repeat(pa.scalar(batch.message, pa.string()), n),
    ]
    arrays.extend(concept_array(columns[c.name]) for c in catalog.concepts)
    return pa.Table.from_arrays(arrays, schema=schema)
