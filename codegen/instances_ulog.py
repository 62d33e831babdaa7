"""PX4 ULog flight logs (.ulg) as records: every record of a uORB message's topics, all multi_ids.

Records come in file order (multi_ids interleaved as logged), each decoded on its own, so memory
does not grow with the number of records beyond the reader's index (one offset per record). A
file given by path is memory-mapped rather than read into memory.

Logs written before a message changed (PX4 logs predating message versioning) carry another
format for the topic: the difference is one notice per topic, fields matching by name and type
are decoded, and the checks of the fields the log lacks or types differently are not reported
(their values would be the schema's defaults, not the log's data) -- with one notice naming them.

The generated reader (``<package>._ulog``) hands out whole lists; walking one record at a time
uses its index (``Log._streams``) and record filler (``_plan``/``_fill``) directly.
"""

from __future__ import annotations

import heapq
import importlib
import mmap
import struct
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import IO, Any

from .instances import InstanceError, Item, Notice, Record, Unreadable
from .ir import Message

MAX_DAMAGE_NOTICES = 10
_D_HEADER = 5  # uint16 size, uint8 type 'D', uint16 msg_id: a record's data starts this far in


@dataclass(frozen=True)
class LogRecord:
    """One decoded record: topic, instance, file offset of its 'D' record, timestamp (us)."""

    topic: str
    multi_id: int
    offset: int
    timestamp: int | None
    instance: Any
    skip: frozenset[str]

    def where(self) -> str:
        stamp = f", timestamp {self.timestamp} us" if self.timestamp is not None else ""
        return f"{self.topic} multi_id {self.multi_id}{stamp}, offset {self.offset}"

    def location(self) -> dict[str, object]:
        return {"topic": self.topic, "multi_id": self.multi_id, "timestamp_us": self.timestamp, "offset": self.offset}


def runtime(model: Any, name: str) -> ModuleType:
    """The generated package's runtime module ``name`` (``_ulog``, ``_mavlink``) of a model class."""
    package = model.__module__.rpartition(".")[0]
    return importlib.import_module(f"{package}.{name}")


def _diff_line(diff: Any) -> str:
    parts = []
    if diff.missing:
        parts.append("missing from the log: " + ", ".join(f"{n} {t}" for n, t in diff.missing))
    if diff.extra:
        parts.append("only in the log: " + ", ".join(f"{n} {t}" for n, t in diff.extra))
    if diff.retyped:
        parts.append("retyped: " + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in diff.retyped))
    body = "; ".join(parts) if parts else "same fields, other layout"
    return f"{diff.topic}: the log's format differs from the schema's ({diff.message}): {body}"


class UlogReader:
    """An opened log and the topics of one generated uORB class; close() releases the file."""

    def __init__(self, source: Path | IO[bytes], name: str, model: Any) -> None:
        self.name = name
        self.model = model
        self.ulog = runtime(model, "_ulog")
        self._map: mmap.mmap | None = None
        data: Any
        if isinstance(source, Path):
            data = self._map = _map_file(source, name)
        else:
            data = source.read()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", self.ulog.ULogWarning)  # listed in Log.warnings
                self.log = self.ulog.Log(data)
                self.log._parse()
        except (ValueError, struct.error, IndexError) as exc:  # ULogError is a ValueError
            self.close()
            raise InstanceError(name, 0, f"expected a ULog file: {exc}") from None
        self.notices: list[Notice] = []
        self.plans: dict[str, tuple[Any, frozenset[str]]] = {}
        self._prepare()

    def close(self) -> None:
        if self._map is not None:
            self._map.close()
            self._map = None

    def _prepare(self) -> None:
        topics = tuple(getattr(self.model, "UORB_TOPICS", ()) or (self.ulog.format_of(self.model).name,))
        present = {t for t, _ in self.log.topics()}
        for text in self.log.warnings[:MAX_DAMAGE_NOTICES]:
            self.notices.append(Notice(self.name, f"damaged log, recovered: {text}", "damage"))
        if len(self.log.warnings) > MAX_DAMAGE_NOTICES:
            more = len(self.log.warnings) - MAX_DAMAGE_NOTICES
            self.notices.append(Notice(self.name, f"damaged log: {more} more problems recovered from", "damage"))
        for topic in topics:
            if topic not in present:
                continue
            try:
                diff = self.log.compare(self.model, topic=topic)
                lay = self.log.layout(topic)
            except ValueError as exc:
                self.notices.append(Notice(self.name, f"{topic}: cannot decode this topic: {exc}", "damage"))
                continue
            skip = frozenset({n for n, _ in diff.missing} | {r.name for r in diff.retyped})
            if not diff.identical:
                severity = "info" if diff.matches else "warning"
                self.notices.append(Notice(self.name, _diff_line(diff), "format-diff", severity, diff.to_dict()))
            if skip:
                self.notices.append(
                    Notice(
                        self.name,
                        f"{topic}: not checked, as the log lacks them or types them differently "
                        f"(their values would be the schema's defaults): {', '.join(sorted(skip))}",
                        "unchecked",
                        data={"topic": topic, "fields": sorted(skip)},
                    )
                )
            self.plans[topic] = (self._decoder(diff, lay, skip), skip)
        if not self.plans:
            logged = ", ".join(sorted(present)) or "none"
            self.notices.append(
                Notice(self.name, f"no {' or '.join(topics)} records in this log (topics logged: {logged})", "empty")
            )

    def _decoder(self, diff: Any, lay: Any, skip: frozenset[str]) -> Any:
        data, size = self.log.data, lay.data_size
        if diff.identical:
            decode = self.model.decode
            return lambda offset: decode(data[offset : offset + size])
        unpack = lay.columns().record_struct(size).unpack_from
        index = {n: i for i, n in enumerate(lay.names)}
        plan = self.ulog._plan(self.ulog.format_of(self.model), index, "", "", set(skip))
        fill, model = self.ulog._fill, self.model
        return lambda offset: fill(model(), plan, unpack(data, offset))

    def records(self) -> Iterator[LogRecord | Unreadable]:
        """Every record of the class's topics in file order (multi_ids interleaved)."""
        streams = getattr(self.log, "_streams", {})
        queues = [_stream(streams[key].offsets, *key) for key in self.log.topics() if key[0] in self.plans]
        for offset, topic, multi_id in heapq.merge(*queues):
            decode, skip = self.plans[topic]
            try:
                obj = decode(offset)
            except (ValueError, struct.error, TypeError) as exc:
                yield Unreadable(self.name, 0, f"{topic} multi_id {multi_id}, offset {offset}: cannot decode: {exc}")
                continue
            stamp = getattr(obj, "timestamp", None) if "timestamp" not in skip else None
            yield LogRecord(topic, multi_id, offset - _D_HEADER, stamp if isinstance(stamp, int) else None, obj, skip)


def _stream(offsets: list[int], topic: str, multi_id: int) -> Iterator[tuple[int, str, int]]:
    for offset in offsets:
        yield offset, topic, multi_id


def _map_file(path: Path, name: str) -> mmap.mmap:
    try:
        with path.open("rb") as f:
            if f.seek(0, 2) == 0:
                raise InstanceError(name, 0, "empty file: expected a ULog file")
            return mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
    except OSError as exc:
        raise InstanceError(name, 0, f"cannot read file: {exc.strerror or exc}") from None


def ulog_items(path: Path, name: str, message: Message, model: Any) -> Iterator[Item]:
    """validate's records of a .ulg file: notices first, then one record per logged message."""
    reader = UlogReader(path, name, model)  # raises InstanceError before the first item
    return _items(reader)


def _items(reader: UlogReader) -> Iterator[Item]:
    try:
        yield from reader.notices
        index = 0
        for rec in reader.records():
            if isinstance(rec, Unreadable):
                yield rec
                continue
            yield Record(
                index,
                0,
                None,
                reader.name,
                where=rec.where(),
                instance=rec.instance,
                skip=rec.skip,
                location=rec.location(),
            )
            index += 1
    finally:
        reader.close()
