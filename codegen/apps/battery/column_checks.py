"""Validation over the battery view's columns: the findings the per-record read gives, without reading twice.

``battgen report`` reads a log through the battery view (:func:`.view.read_view`); the validator's findings used to
need a second, record-by-record read. Here the rows are checked where they lie in the view's columns: a numpy mask
picks the rows that some check of the generated ``validate()`` can flag (:func:`flaggable`), and only those rows
are built as the generated class (from the row's values) and run through :meth:`Checker.check`, so rule ids,
messages and their order are the oracle's own. A row no check can flag gives no finding and costs no Python.

A finding is placed as the per-record reader places it (:func:`codegen.inputs.ulog.records.ulog_items`: topic,
multi_id, timestamp_us, offset and the record's index in file order). A ULog batch does not carry its records'
offsets, so they come from the log's index (the C walk, no decoding); the format notices from the per-record
reader's definitions. Where the batch lacks what a kind needs (a tlog's frame number, sysid/compid/seq and offset;
a ULog whose values may not fit the schema's types or whose walk met damage), :func:`column_findings` returns
None and the caller reads the records a second time for that kind only.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ...backends.python import naming
from ...inputs.model import GeneratedMessage, MessageClass, UorbClass
from ...inputs.records import Notice, Record, Unreadable
from ...inputs.ulog.columns import record_dtype
from ...inputs.ulog.index import record_offsets
from ...inputs.ulog.records import LogRecord, UlogReader
from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType
from .columns import NDArray, length_key
from .view import Chunk


class Checker(Protocol):
    """The per-record validator (:class:`codegen.apps.gate.validate.Checker`; not imported: the validator's app
    imports the battery view)."""

    cls: MessageClass
    message: Message
    rules: Mapping[str, frozenset[str]]

    def check(self, record: Record) -> Sequence[Finding]: ...


Finding = Any  # a :class:`codegen.apps.gate.validate.Finding`, as the checker makes it

_D_HEAD = 5  # a ULog data record's payload starts this far after the record (uint16 size, 'D', uint16 msg_id)


@dataclass
class Checked:
    """What the per-record read would have given the report: findings as (t, battery, finding), notices and
    unreadable parts."""

    findings: list[tuple[float, int, Finding]] = field(default_factory=list)
    notices: list[Notice] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)
    groups: list[FindingGroup] = field(default_factory=list)  # the findings grouped, where asked for instead


@dataclass
class FindingGroup:
    """The findings of one battery that share a rule, a field path and a severity: how many, and the first of them
    in file order (its record's index, ``t`` and message). What a report shows of a million alike findings."""

    battery: int
    rule: str
    path: str
    severity: str
    count: int
    first: int  # the first finding's record index in file order
    t: float
    message: str


def group_findings(findings: Iterable[tuple[float, int, Finding]]) -> list[FindingGroup]:
    """Findings as (t, battery, finding), in file order, as groups (:func:`ordered`)."""
    groups: dict[tuple[int, str, str, str], FindingGroup] = {}
    for t, battery, f in findings:
        key = (battery, str(f.rule), str(f.path), str(f.severity))
        group = groups.get(key)
        if group is None:
            groups[key] = FindingGroup(battery, key[1], key[2], key[3], 1, int(f.record), t, str(f.message))
        else:
            group.count += 1
    return ordered(groups.values())


def ordered(groups: Iterable[FindingGroup]) -> list[FindingGroup]:
    """Groups by battery, then where each first appears in the file."""
    return sorted(groups, key=lambda g: (g.battery, g.first, g.rule, g.path, g.severity))


def flaggable(checker: Checker, columns: Mapping[str, NDArray], n: int) -> NDArray:
    """The rows some check of ``validate()`` may flag: a superset (a row outside it has no finding).

    Each field's check reads that field alone, so a value is judged once: the generated validator itself runs on
    the class's default record holding that value (:class:`_Probe`), and the rows holding a value it flags are
    flaggable. A float field's values inside its range (and the float32 range) pass without asking; a column of
    too many other values is flaggable wherever such a value lies. A cross-field rule reads several fields: it is
    masked only where its mask below is known to be exact (:data:`_RULE_MASKS`, tested against the oracle);
    a message with any other rule has every row flaggable."""
    rule_masks = [_RULE_MASKS.get((checker.message.qualified_name, rule)) for rule in checker.rules]
    if any(m is None for m in rule_masks) or any(f.name not in columns for f in checker.message.fields):
        return np.ones(n, bool)  # an unmasked rule; or a field at the record's default (not a column here)
    mask = np.zeros(n, bool)
    for rule_mask in rule_masks:
        if rule_mask is not None:
            mask |= rule_mask(columns, n)
    probe = _Probe(checker)
    for f in checker.message.fields:
        if mask.all():
            break
        if not f.is_padding:
            mask |= _field_mask(probe, f, columns[f.name], n)
    return mask


_MAX_PROBES = 256  # values of one column judged one by one; beyond, every row holding an unjudged value
_FLOAT_MAX = {32: float(np.finfo(np.float32).max), 64: float(np.finfo(np.float64).max)}


class _Probe:
    """The generated validator on the class's default record holding one field's value: does that field's own
    check flag it (cross-field rules left out; they are masked apart)."""

    def __init__(self, checker: Checker) -> None:
        self.cls: Any = checker.cls
        self.seen: dict[tuple[str, object], bool] = {}

    def flags(self, f: Field, value: object) -> bool:
        key = (f.name, value if value == value else "nan")  # NaN: one key
        found = self.seen.get(key)
        if found is None:
            record = self.cls()
            setattr(record, naming.field_identifier(f.name, f.pattern), value)
            name = f.name
            found = any(
                not str(v.rule).startswith("cross-field:")
                and (str(v.path) == name or str(v.path).startswith((name + "[", name + ".")))
                for v in record.validate()
            )
            self.seen[key] = found
        return found


def _field_mask(probe: _Probe, f: Field, column: NDArray, n: int) -> NDArray:
    """Rows whose value of one field its check may flag."""
    ftype = f.type
    if column.ndim == 2:
        return _array_mask(f, column, n)
    suspect = np.ones(n, bool)
    plain = not (f.enums or f.const is not None or f.choices or f.required)
    if plain and isinstance(ftype, PrimitiveType) and _numeric(ftype, column):
        suspect = ~_inside(f, ftype, column)  # a (finite) value in range passes whatever the sentinel
    if column.dtype == object or not suspect.any():
        return suspect if column.dtype != object else np.ones(n, bool)
    values = column[suspect]
    unique = np.unique(values)
    if len(unique) > _MAX_PROBES:
        return suspect
    flagged = [v for v in unique.tolist() if probe.flags(f, v)]
    if not flagged:
        return np.zeros(n, bool)
    out = np.zeros(n, bool)
    hit = np.isin(values, np.array(flagged, values.dtype))
    if values.dtype.kind == "f" and any(v != v for v in flagged):
        hit |= np.isnan(values)
    out[np.nonzero(suspect)[0][hit]] = True
    return out


def _numeric(ftype: PrimitiveType, column: NDArray) -> bool:
    kind = str(column.dtype.kind)
    if ftype.kind is PrimitiveKind.FLOAT:
        return kind == "f"
    return ftype.kind in (PrimitiveKind.INT, PrimitiveKind.UINT) and kind in ("i", "u")


def _inside(f: Field, ftype: PrimitiveType, column: NDArray) -> NDArray:
    """Where a number lies within its type's range (a float: finite) and strictly inside its field's range (the
    bounds themselves are probed)."""
    with np.errstate(invalid="ignore"):
        if ftype.kind is PrimitiveKind.FLOAT:
            limit = _FLOAT_MAX.get(ftype.bits, _FLOAT_MAX[32])
            ok = np.isfinite(column) & (np.abs(column) <= limit)
        else:
            lo, hi = _int_range(ftype)
            ok = (column >= lo) & (column <= hi) if column.dtype.kind == "i" else column <= hi
        if f.range is not None and f.range.minimum is not None:
            ok &= column > float(f.range.minimum)
        if f.range is not None and f.range.maximum is not None:
            ok &= column < float(f.range.maximum)
    return np.asarray(ok, bool)


def _int_range(ftype: PrimitiveType) -> tuple[int, int]:
    if ftype.kind is PrimitiveKind.UINT:
        return 0, (1 << ftype.bits) - 1
    return -(1 << (ftype.bits - 1)), (1 << (ftype.bits - 1)) - 1


def _array_mask(f: Field, column: NDArray, n: int) -> NDArray:
    """An array's rows: a plain float array (no range, enum or choices) passes where every element is a finite
    float32; any other array is flaggable everywhere."""
    ftype = f.type
    element = ftype.element if isinstance(ftype, ArrayType) else None
    plain = not (f.enums or f.const is not None or f.choices or f.required or f.range)
    if not (plain and isinstance(element, PrimitiveType) and element.kind is PrimitiveKind.FLOAT):
        return np.ones(n, bool)
    if not isinstance(ftype, ArrayType) or ftype.capacity != column.shape[1] or column.dtype.kind != "f":
        return np.ones(n, bool)  # a width the schema's check would flag (or a dynamic length): judged per record
    limit = _FLOAT_MAX.get(element.bits, _FLOAT_MAX[32])
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(column) & (np.abs(column) <= limit)
    return np.asarray(~ok.all(axis=1), bool)


def _cell_count_capacity(columns: Mapping[str, NDArray], n: int) -> NDArray:
    """uorb.BatteryStatus ``cell-count-capacity``: ``cell_count <= len(voltage_cell_v)``."""
    cells = columns["voltage_cell_v"]
    return np.asarray(columns["cell_count"] > cells.shape[1], bool)


def _cells_beyond_count_zero(columns: Mapping[str, NDArray], n: int) -> NDArray:
    """uorb.BatteryStatus ``cells-beyond-count-zero``: where ``cell_count != 0``, every cell from ``cell_count``
    on is 0 (NaN is not)."""
    cells = columns["voltage_cell_v"]
    count = np.asarray(columns["cell_count"], np.int64)
    beyond = np.arange(cells.shape[1])[None, :] >= np.maximum(count, 0)[:, None]
    return np.asarray((count != 0) & (beyond & (cells != 0)).any(axis=1), bool)


# Cross-field rules masked over columns, by (message, rule id): each the rule's condition restated in numpy,
# proved against the generated validator by tests/apps/test_column_checks.py. Any other rule: every row.
_RULE_MASKS: dict[tuple[str, str], Callable[[Mapping[str, NDArray], int], NDArray]] = {
    ("uorb.BatteryStatus", "cell-count-capacity"): _cell_count_capacity,
    ("uorb.BatteryStatus", "cells-beyond-count-zero"): _cells_beyond_count_zero,
}


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


def column_finding_groups(
    path: Path, name: str, kind: str, chunks: Iterable[Chunk], checker: Checker
) -> tuple[list[FindingGroup], list[Notice], list[Unreadable]] | None:
    """As :func:`column_findings`, the findings as groups (:func:`group_findings` of them, exactly), without a
    finding made per record: a value of a field that its own check flags is judged once (the oracle on the class's
    default record holding it), and its rows counted over the column; only rows a cross-field rule or an array's
    check may flag, or whose column holds too many values to judge one by one, go through the oracle row by row."""
    if kind != "ulog" or not isinstance(checker.cls, UorbClass) or len(checker.cls.UORB_TOPICS) != 1:
        return None
    checked = _ulog_findings(path, name, list(chunks), checker, grouped=True)
    if checked is None:
        return None
    return checked.groups, checked.notices, checked.unreadable


def _ulog_findings(
    path: Path, name: str, chunks: list[Chunk], checker: Checker, *, grouped: bool = False
) -> Checked | None:
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
        if rows and grouped:
            out.groups = _grouped_rows(name, rows, chunks, checker, topic, skip)
        elif rows:
            out.findings = _checked_rows(name, rows, chunks, checker, topic, skip)
        out.notices += reader.after_walk()
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


def _placed(rows: list[_Rows], chunks: list[Chunk], skip: frozenset[str]) -> tuple[NDArray, NDArray, NDArray] | None:
    """The rows' file order (argsort of their offsets), each row's index in it (``ulog_items``' index) and its
    ``timestamp`` as the reader reports it; None for no rows."""
    every = np.concatenate([r.offsets for r in rows])
    if len(every) != sum(chunks[r.chunk].n for r in rows):
        raise ValueError("the view's rows and the log's index disagree")  # a bug, never a quiet misplacement
    if not len(every):
        return None
    order = np.argsort(every, kind="stable")
    index = np.empty(len(every), np.int64)
    index[order] = np.arange(len(every))
    return order, index, np.concatenate([_stamps(chunks[r.chunk], skip) for r in rows])


def _record(
    name: str, topic: str, multi_id: int, offset: int, stamp: Any, index: int, instance: Any, skip: frozenset[str]
) -> Record:
    """A row as the per-record reader yields it (:func:`codegen.inputs.ulog.records.ulog_items`): its place in the
    log."""
    rec = LogRecord(topic, multi_id, offset, int(stamp) if stamp >= 0 else None, instance, skip, {}, ())
    return Record(index, 0, None, name, where=rec.where(), instance=instance, skip=skip, location=rec.location())


def _checked_rows(
    name: str, rows: list[_Rows], chunks: list[Chunk], checker: Checker, topic: str, skip: frozenset[str]
) -> list[tuple[float, int, Finding]]:
    placed = _placed(rows, chunks, skip)
    if placed is None:
        return []
    order, index, stamps_all = placed
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
            record = _record(name, topic, multi_id, offset, stamps_all[at], int(index[at]), instance, skip)
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


class _FieldFindings:
    """The oracle's findings of one field's value alone (on the class's default record holding it; cross-field
    rules left out), each value asked once."""

    def __init__(self, checker: Checker, name: str, skip: frozenset[str]) -> None:
        self.checker = checker
        self.cls: Any = checker.cls
        self.name = name
        self.skip = skip
        self.seen: dict[tuple[str, object], list[Finding]] = {}

    def of(self, f: Field, value: object) -> list[Finding]:
        key = (f.name, value if value == value else "nan")
        found = self.seen.get(key)
        if found is None:
            instance = self.cls()
            setattr(instance, naming.field_identifier(f.name, f.pattern), value)
            record = Record(0, 0, None, self.name, instance=instance, skip=self.skip)
            own = (f.name + "[", f.name + ".")
            found = [
                x
                for x in self.checker.check(record)
                if not str(x.rule).startswith("cross-field:") and (str(x.path) == f.name or str(x.path).startswith(own))
            ]
            self.seen[key] = found
        return found


def _rule_rows(checker: Checker, columns: Mapping[str, NDArray], n: int) -> NDArray:
    """The rows a cross-field rule may flag (every row where a rule has no exact mask, or a field lacks a column)."""
    masks = [_RULE_MASKS.get((checker.message.qualified_name, rule)) for rule in checker.rules]
    if any(m is None for m in masks) or any(f.name not in columns for f in checker.message.fields):
        return np.ones(n, bool)
    out = np.zeros(n, bool)
    for mask in masks:
        if mask is not None:
            out |= mask(columns, n)
    return out


def _grouped_rows(
    name: str, rows: list[_Rows], chunks: list[Chunk], checker: Checker, topic: str, skip: frozenset[str]
) -> list[FindingGroup]:
    """:func:`_checked_rows`' findings as groups (see :func:`column_finding_groups`)."""
    placed = _placed(rows, chunks, skip)
    if placed is None:
        return []
    order, index, stamps_all = placed
    t0 = _seconds(stamps_all[int(order[0])], int(index[int(order[0])]))
    groups: dict[tuple[int, str, str, str], FindingGroup] = {}

    def add(battery: int, finding: Finding, count: int, at: int) -> None:
        key = (battery, str(finding.rule), str(finding.path), str(finding.severity))
        first = int(index[at])
        group = groups.get(key)
        if group is None:
            t = _seconds(stamps_all[at], first) - t0
            groups[key] = FindingGroup(battery, key[1], key[2], key[3], count, first, t, str(finding.message))
            return
        group.count += count
        if first < group.first:
            group.first, group.t, group.message = first, _seconds(stamps_all[at], first) - t0, str(finding.message)

    values = _FieldFindings(checker, name, skip)
    probe = _Probe(checker)
    start = 0
    for r in rows:
        chunk = chunks[r.chunk]
        columns, n = chunk.batch.columns, chunk.n
        multi_id = int(chunk.batch.instance[0]) if n else 0
        full = _rule_rows(checker, columns, n)
        flagged_fields: list[tuple[Field, NDArray]] = []
        for f in checker.message.fields:
            if f.is_padding or f.name not in columns or full.all():
                continue
            column = columns[f.name]
            mask = _field_mask(probe, f, column, n)
            if not mask.any():
                continue
            judged = column.ndim == 1 and column.dtype != object
            if judged:
                unique = np.unique(column[mask & ~full])
                judged = len(unique) <= _MAX_PROBES
            if judged:
                flagged_fields.append((f, mask))
            else:
                full |= mask  # an array, or a column of too many values to judge one by one: the oracle per row
        picked = np.nonzero(full)[0]
        for row, instance in zip(
            picked.tolist(), row_instances(checker.cls, checker.message, columns, picked), strict=True
        ):
            at = start + row
            offset = int(r.offsets[row]) - _D_HEAD
            record = _record(name, topic, multi_id, offset, stamps_all[at], int(index[at]), instance, skip)
            for finding in checker.check(record):
                add(multi_id, finding, 1, at)
        for f, mask in flagged_fields:
            where = np.nonzero(mask & ~full)[0]
            column = columns[f.name][where]
            for value in np.unique(column).tolist():
                same = where[column == value] if value == value else where[np.isnan(column)]
                if not len(same):
                    continue
                found = values.of(f, value)
                if not found:
                    continue
                positions = start + same
                at = int(positions[int(np.argmin(index[positions]))])
                for finding in found:
                    add(multi_id, finding, len(same), at)
        start += n
    return ordered(groups.values())
