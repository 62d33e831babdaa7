"""Validation over the battery view's columns: the findings the per-record read gives, without reading twice.

``battgen report`` reads a log through the battery view (:func:`.view.read_view`); the validator's findings used to
need a second, record-by-record read. Here the rows are checked where they lie in the view's columns: a numpy mask
picks the rows that some check of the generated ``validate()`` can flag (:func:`flaggable`), and only those rows
are built as the generated class (from the row's values) and run through :meth:`Checker.check`, so rule ids,
messages and their order are the oracle's own. A row no check can flag gives no finding and costs no Python.

A finding is placed as the per-record reader places it (:func:`codegen.inputs.ulog.ulog_items`: topic,
multi_id, timestamp_us, offset and the record's index in file order). A ULog batch does not carry its records'
offsets, so they come from the log's index (the C walk, no decoding); the format notices from the per-record
reader's definitions. Where the batch lacks what a kind needs (a tlog's frame number, sysid/compid/seq and offset;
a ULog whose values may not fit the schema's types or whose walk met damage), :func:`column_findings` returns
None and the caller reads the records a second time for that kind only.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ...backends.python import naming
from ...inputs.model import GeneratedMessage, MessageClass, UorbClass
from ...inputs.records import Notice, Record, Unreadable
from ...inputs.ulog import LogRecord, UlogReader
from ...inputs.ulog_columns import record_dtype
from ...inputs.ulog_index import record_offsets
from ...ir import Field, Message, PrimitiveKind, PrimitiveType
from .columns import NDArray, length_key
from .view import Chunk


class Checker(Protocol):
    """The per-record validator (:class:`codegen.apps.validate.Checker`; not imported: the validator's app
    imports the battery view)."""

    cls: MessageClass
    message: Message
    rules: Mapping[str, frozenset[str]]

    def check(self, record: Record) -> Sequence[Finding]: ...


Finding = Any  # a :class:`codegen.apps.validate.Finding`, as the checker makes it

_D_HEAD = 5  # a ULog data record's payload starts this far after the record (uint16 size, 'D', uint16 msg_id)


@dataclass
class Checked:
    """What the per-record read would have given the report: findings as (t, battery, finding), notices and
    unreadable parts."""

    findings: list[tuple[float, int, Finding]] = field(default_factory=list)
    notices: list[Notice] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)


def flaggable(checker: Checker, columns: Mapping[str, NDArray], n: int) -> NDArray:
    """The rows some check of ``validate()`` may flag (a superset: a row outside it has no finding).

    A message with cross-field rules (:func:`codegen.ir.rules.bound_rules`) has every row flaggable: a rule's
    expression reads several fields and is not masked here."""
    if checker.rules:
        return np.ones(n, bool)
    mask = np.zeros(n, bool)
    for f in checker.message.fields:
        if f.is_padding:
            continue
        column = columns.get(f.name)
        if column is None:  # the record's default: checked once, it flags every row or none
            return np.ones(n, bool)
        mask |= _field_mask(f, column, n)
    return mask


def _field_mask(f: Field, column: NDArray, n: int) -> NDArray:
    """Rows whose value of one field may fail its check: conservative (every row) unless the field is a plain
    number with no constraint, whose check is its type's range (and a float's NaN/inf, left to the check)."""
    ftype = f.type
    constrained = f.range or f.invalid or f.enums or f.const is not None or f.choices or f.required
    if constrained or not isinstance(ftype, PrimitiveType) or column.dtype == object:
        return np.ones(n, bool)
    if ftype.kind is PrimitiveKind.FLOAT:
        return np.asarray(~np.isfinite(column), bool) if column.dtype.kind == "f" else np.ones(n, bool)
    if ftype.kind in (PrimitiveKind.INT, PrimitiveKind.UINT) and column.dtype.kind in "iu":
        lo, hi = _int_range(ftype)
        return np.asarray((column < lo) | (column > hi), bool)
    if ftype.kind is PrimitiveKind.BOOL and column.dtype == np.bool_:
        return np.zeros(n, bool)
    return np.ones(n, bool)


def _int_range(ftype: PrimitiveType) -> tuple[int, int]:
    if ftype.kind is PrimitiveKind.UINT:
        return 0, (1 << ftype.bits) - 1
    return -(1 << (ftype.bits - 1)), (1 << (ftype.bits - 1)) - 1


def row_instance(cls: MessageClass, message: Message, columns: Mapping[str, NDArray], row: int) -> GeneratedMessage:
    """One row of the columns as the generated class (the values the per-record decoder gives)."""
    return row_instances(cls, message, columns, np.array([row]))[0]


def row_instances(
    cls: MessageClass, message: Message, columns: Mapping[str, NDArray], rows: NDArray
) -> list[GeneratedMessage]:
    """Rows of the columns as the generated class: each column's rows turned into Python values at once (a
    numpy ``tolist``), then one constructor call a row."""
    names: list[str] = []
    values: list[list[Any]] = []
    for f in message.fields:
        if f.is_padding or f.name not in columns:
            continue
        column = columns[f.name][rows]
        width = columns.get(length_key(f.name))
        if column.ndim == 2 and width is not None:
            cells = column.tolist()
            values.append([c[: int(w)] for c, w in zip(cells, width[rows].tolist(), strict=True)])
        else:
            values.append(column.tolist())  # an object column's values stay as they are
        names.append(naming.field_identifier(f.name, f.pattern))
    make: Any = cls
    if not names:
        return []
    if tuple(names) == tuple(f.name for f in dataclasses.fields(make)):  # the constructor's order: positional
        return [make(*row) for row in zip(*values, strict=True)]
    return [make(**dict(zip(names, row, strict=True))) for row in zip(*values, strict=True)]


def column_findings(path: Path, name: str, kind: str, chunks: Iterable[Chunk], checker: Checker) -> Checked | None:
    """The report's findings of a log read through the view, from the view's columns (``chunks`` read with
    ``all_fields=True``, in the view's order); None where the columns lack what this kind needs."""
    if kind != "ulog" or not isinstance(checker.cls, UorbClass) or len(checker.cls.UORB_TOPICS) != 1:
        return None
    return _ulog_findings(path, name, list(chunks), checker)


def _ulog_findings(path: Path, name: str, chunks: list[Chunk], checker: Checker) -> Checked | None:
    model = checker.cls
    topic = model.UORB_TOPICS[0]  # type: ignore[attr-defined]
    reader = UlogReader(path, name, model)
    try:
        skip = reader.skips.get(topic)
        if skip is None:  # the topic is absent or undecodable: the per-record read says so
            return None
        offsets = record_offsets(reader.log)  # walks the log: its warnings and topics, as the record walk leaves them
        if reader.log.warnings:
            return None  # damage: the per-record walk's Unreadable parts and order
        if not _all_fit(reader, topic, [v for k, v in offsets.items() if k[0] == topic]):
            return None  # a value the schema's type cannot hold: the per-record decoder's "unfit" notice
        out = Checked(notices=list(reader.notices))
        rows = list(_located_rows(chunks, offsets, topic))
        if rows:
            out.findings = _checked_rows(name, rows, chunks, checker, topic, skip)
        out.notices += _after_walk(reader)
        return out
    finally:
        reader.close()


def _all_fit(reader: UlogReader, topic: str, offsets: list[NDArray]) -> bool:
    """Whether every value of a field the log types otherwise than the schema (an older PX4's ``int32``
    ``cell_count``) fits the schema's type, as the generated decoder's conversion judges (else it leaves the
    default and tells an "unfit" notice the columns do not carry). Read from the raw records, no decoding."""
    diff = reader.log.compare(reader.model, topic=topic)
    if not diff.converted:
        return True
    if not offsets:
        return True
    log: Any = reader.log  # the generated Log: its memory map and layouts
    lay = log.layout(topic)
    dtype = record_dtype(lay)
    data = log.data
    at_every_byte = np.ndarray(
        buffer=data, dtype=np.dtype((np.void, lay.data_size)), shape=(len(data) - lay.data_size + 1,), strides=(1,)
    )
    records = at_every_byte[np.concatenate(offsets)].view(dtype)
    log_names = {new: old for old, new in diff.renamed}
    for r in diff.converted:
        name = log_names.get(r.name, r.name)
        base, _, count = r.schema.partition("[")
        if name not in (dtype.names or ()):
            return False
        values = np.asarray(records[name])
        if values.ndim == 2:
            values = values[:, : int(count.rstrip("]") or 0)]
        fits = _fits(base, values)
        if fits is None or not fits.all():
            return False
    return True


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _fits(ctype: str, values: NDArray) -> NDArray | None:
    """Where values fit a C type (NaN and infinities fit a float); None for a type not judged here."""
    if ctype == "double":
        return np.ones(values.shape, bool)
    if ctype == "float":
        return np.asarray(~np.isfinite(values) | (np.abs(values) <= _FLOAT32_MAX), bool)
    match = re.fullmatch(r"(u?)int(8|16|32|64)_t", ctype)
    if match is None:
        return None
    bits = int(match.group(2))
    lo, hi = (0, (1 << bits) - 1) if match.group(1) else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
    if values.dtype.kind in "iu":
        return np.asarray((values >= lo) & (values <= hi), bool)
    return np.asarray((values >= lo) & (values <= hi), bool) if values.dtype.kind == "f" else None


def _after_walk(reader: UlogReader) -> list[Notice]:
    return reader._after_walk()


@dataclass
class _Rows:
    chunk: int
    offsets: NDArray  # payload offsets of the chunk's rows


def _located_rows(chunks: list[Chunk], offsets: Mapping[tuple[str, int], NDArray], topic: str) -> Iterator[_Rows]:
    begun: dict[int, int] = {}
    for k, chunk in enumerate(chunks):
        multi_id = int(chunk.batch.instance[0]) if chunk.n else 0
        begin = begun.get(multi_id, 0)
        begun[multi_id] = begin + chunk.n
        yield _Rows(k, offsets.get((topic, multi_id), np.zeros(0, np.int64))[begin : begin + chunk.n])


def _checked_rows(
    name: str, rows: list[_Rows], chunks: list[Chunk], checker: Checker, topic: str, skip: frozenset[str]
) -> list[tuple[float, int, Finding]]:
    every = np.concatenate([r.offsets for r in rows])
    if len(every) != sum(chunks[r.chunk].n for r in rows):
        raise ValueError("the view's rows and the log's index disagree")  # a bug, never a quiet misplacement
    if not len(every):
        return []
    order = np.argsort(every, kind="stable")
    index = np.empty(len(every), np.int64)
    index[order] = np.arange(len(every))  # the record's position in file order (ulog_items' index)
    stamps_all = np.concatenate([_stamps(chunks[r.chunk], skip) for r in rows])
    first = int(order[0])
    t0 = _seconds(stamps_all[first], int(index[first]))
    found: list[tuple[int, float, int, Finding]] = []
    start = 0
    for r in rows:
        chunk = chunks[r.chunk]
        columns = chunk.batch.columns
        multi_id = int(chunk.batch.instance[0])
        picked = np.nonzero(flaggable(checker, columns, chunk.n))[0]
        instances = row_instances(checker.cls, checker.message, columns, picked)
        offsets = (r.offsets[picked] - _D_HEAD).tolist()
        for row, instance, offset in zip(picked.tolist(), instances, offsets, strict=True):
            at = start + row
            stamp = int(stamps_all[at]) if stamps_all[at] >= 0 else None
            rec = LogRecord(topic, multi_id, offset, stamp, instance, skip, {}, ())
            record = Record(
                int(index[at]), 0, None, name, where=rec.where(), instance=instance, skip=skip,
                location=rec.location(),
            )  # fmt: skip
            t = _seconds(stamps_all[at], int(index[at])) - t0
            for finding in checker.check(record):
                found.append((int(index[at]), t, multi_id, finding))
        start += chunk.n
    found.sort(key=lambda x: x[0])  # stable: the validator's order within a record
    return [(t, battery, finding) for _, t, battery, finding in found]


def _stamps(chunk: Chunk, skip: frozenset[str]) -> NDArray:
    """The records' ``timestamp`` as the reader reports it (-1: none, as where the log lacks the field)."""
    stamps = chunk.batch.columns.get("timestamp")
    if stamps is None or "timestamp" in skip:
        return np.full(chunk.n, -1, np.int64)
    return np.asarray(stamps, np.int64)


def _seconds(stamp: Any, index: int) -> float:
    """The report's time of a record (:func:`codegen.apps.report.series._time`): its timestamp, else its position."""
    return int(stamp) / 1e6 if stamp >= 0 else float(index)
