"""The fleet table as Arrow: one schema for every log, concept columns in SI units, unknown as null.

Columns: the context of each record (``log``, ``source``, ``vehicle``, ``battery``, ``t``,
``time``, ``message``), then one column per shared concept in the order concepts.yaml lists them.
Each concept column's field metadata holds its ``unit`` and ``quantity`` (from the IR's unit
registry), its ``kind``, its doc, and ``source_fields``: per source message, the fields it is
read from (JSON), so a reader of the Parquet files knows what each value means without battgen.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa

from ..battery.catalog import Catalog
from ..battery.columns import ConceptColumn, NDArray
from ..battery.sources import Batch
from ..battery.view import battery_of
from . import arrow

# Text that repeats (the log, its file, a choice among a few) is dictionary-encoded in Arrow: Parquet
# stores it so anyway, and building it so is a fraction of the cost. Engines read it as text.
_LABEL = pa.dictionary(pa.int32(), pa.string())

_ARROW_TYPES: dict[str, Any] = {
    "number": pa.float64(),
    "integer": pa.int64(),
    "bool": pa.bool_(),
    "text": pa.string(),
    "choice": _LABEL,
    "flags": pa.list_(pa.string()),
    "list": pa.list_(pa.float64()),
}

# the context of every record: (name, Arrow type, doc, unit)
CONTEXT: tuple[tuple[str, Any, str, str | None], ...] = (
    # plain text: the Hive partition key too, which engines read from the path as text
    (
        "log",
        pa.string(),
        "stable id of the log's content (first 16 hex digits of its XXH3-128; older datasets: SHA-256)",
        None,
    ),
    ("source", _LABEL, "file name of the log", None),
    ("vehicle", _LABEL, "the vehicle, where the log says (ULog sys_uuid or hardware, MAVLink system id)", None),
    ("battery", pa.int32(), "battery instance (the concept battery_index where known, else the log's instance)", None),
    ("t", pa.float64(), "seconds since the log's start", "s"),
    ("time", pa.timestamp("us", tz="UTC"), "time of day (UTC), where the log has it", None),
    ("armed", pa.bool_(), "whether the vehicle was armed, where the log says (ULog actuator_armed)", None),
    ("message", _LABEL, "the source message (qualified name) the record was decoded as", None),
)


_SCHEMAS: dict[int, tuple[Catalog, Any]] = {}  # by id(catalog), the catalog kept so the id stays its own


def battery_schema(catalog: Catalog) -> Any:
    """The Arrow schema of the battery table (the same for every log and format; made once per
    catalog, a few milliseconds that each log of a fleet would otherwise pay)."""
    known = _SCHEMAS.get(id(catalog))
    if known is None:
        known = _SCHEMAS[id(catalog)] = (catalog, _battery_schema(catalog))
    return known[1]


def _battery_schema(catalog: Catalog) -> Any:
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
    valid = col.valid
    if col.blank:  # a concept the source never gives (most of them): no arrays to look at or build
        return nulls(len(valid), _ARROW_TYPES[kind])
    everywhere = bool(valid.all())
    if not everywhere and not valid.any():
        return nulls(len(valid), _ARROW_TYPES[kind])
    invalid = None if everywhere else ~valid
    if kind == "number":
        return floats(col.values, invalid)
    if kind in ("integer", "bool"):
        return arrow.array(col.values, _ARROW_TYPES[kind], invalid)
    if kind == "text":
        return arrow.strings(col.values, invalid)
    choices = _words(tuple(col.concept.choices))
    if kind == "choice":
        return pa.DictionaryArray.from_arrays(arrow.array(col.values.astype(np.int32), pa.int32(), invalid), choices)
    if kind == "flags":
        return _flag_lists(col.values, valid, tuple(col.concept.choices), invalid)
    assert col.lengths is not None
    lengths = np.where(valid, col.lengths, 0)
    width = int(lengths[0]) if len(lengths) else 0
    if everywhere and bool((lengths == width).all()):  # every row as long (a pack's cells): no gather
        flat = np.ascontiguousarray(col.values[:, :width]).reshape(-1)
    else:
        flat = col.values[np.arange(col.values.shape[1]) < lengths[:, None]]
    return _lists(lengths, floats(flat), invalid)


def floats(values: NDArray, invalid: NDArray | None = None) -> Any:
    """float64 values as Arrow, NaN (and where ``invalid``) null: with none of either (the usual),
    the array as it is, no copy; else with a validity bitmap. (pyarrow's own NaN scan, ``from_pandas``,
    took 4x the mask's time and 15x numpy's ``isnan``.)"""
    null = np.isnan(values)
    if invalid is not None:
        null |= invalid
    return arrow.array(values, pa.float64(), null)


def _flag_lists(bits: NDArray, valid: NDArray, choices: tuple[str, ...], invalid: NDArray | None) -> Any:
    """Bit sets as lists of their choices' names; rows without a bit set (the usual) cost nothing."""
    rows = np.flatnonzero(np.where(valid, bits, 0))
    counts = np.zeros(len(bits), np.int32)
    names: list[str] = []
    if len(rows):
        set_bits = ((bits[rows, None] >> np.arange(len(choices))) & 1).astype(bool)
        counts[rows] = set_bits.sum(axis=1)
        names = [choices[i] for i in np.nonzero(set_bits)[1].tolist()]
    return _lists(counts, arrow.strings(names), invalid)


def _lists(lengths: NDArray, items: Any, invalid: NDArray | None) -> Any:
    """A list array of ``items`` split into rows of ``lengths``; null rows where ``invalid``."""
    offsets = np.zeros(len(lengths) + 1, np.int32)
    np.cumsum(lengths, out=offsets[1:])
    mask = None if invalid is None else arrow.array(invalid, pa.bool_())
    return pa.ListArray.from_arrays(arrow.array(offsets, pa.int32()), items, mask=mask)


@functools.lru_cache(maxsize=1024)
def _words(words: tuple[str, ...]) -> Any:
    """One Arrow array per set of words, so every chunk of a log's table has the same dictionary
    object for a label or choice column."""
    return arrow.strings(words)


# The caches below hold arrays of a chunk's length: every chunk of a log but its last has the same,
# so they serve a log's chunks; they are small because entries of other lengths or logs are dead
# weight (up to a megabyte each) in a worker that exports a fleet.


@functools.lru_cache(maxsize=32)
def nulls(n: int, typ: Any) -> Any:
    """``n`` nulls of ``typ``. Arrow arrays are immutable, so the chunks of a log share one: a
    format leaves most concepts unknown, and zeroed buffers for each of them in every chunk were a
    tenth of the conversion's time."""
    return pa.nulls(n, typ)


@functools.lru_cache(maxsize=4)
def _zeros(n: int) -> Any:
    return arrow.array(np.zeros(n, np.int32), pa.int32())


def label(text: str, n: int) -> Any:
    """``text`` ``n`` times, dictionary-encoded (its indices shared as :func:`nulls` are)."""
    return pa.DictionaryArray.from_arrays(_zeros(n), _words((text,)))


@functools.lru_cache(maxsize=4)
def repeated(text: str, n: int) -> Any:
    """``text`` ``n`` times as plain text (the log id, which is its Hive partition key too)."""
    return arrow.repeat(text, n)


def battery_table(
    catalog: Catalog, schema: Any, columns: Mapping[str, ConceptColumn], batch: Batch, log: str, source: str
) -> Any:
    """The battery table of one batch of records of the log ``log`` (its content id), file ``source``."""
    n = batch.n
    battery = battery_of(columns, batch)
    timestamp = pa.timestamp("us", tz="UTC")
    arrays: list[Any] = [
        repeated(log, n),
        label(source, n),
        nulls(n, _LABEL)
        if batch.vehicle is None
        else label(batch.vehicle, n)
        if isinstance(batch.vehicle, str)
        else arrow.strings(batch.vehicle).dictionary_encode(),
        arrow.array(battery, pa.int32()),
        floats(batch.t),
        nulls(n, timestamp)
        if batch.time_us is None
        else arrow.array(batch.time_us, timestamp, None if batch.time_known is None else ~batch.time_known),
        nulls(n, pa.bool_())
        if batch.armed is None
        else arrow.array(batch.armed == 1.0, pa.bool_(), np.isnan(batch.armed)),
        label(batch.message, n),
    ]
    arrays.extend(concept_array(columns[c.name]) for c in catalog.concepts)
    return pa.Table.from_arrays(arrays, schema=schema)
