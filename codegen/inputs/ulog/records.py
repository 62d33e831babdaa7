"""PX4 ULog flight logs (.ulg) as records: every record of a uORB message's topics, all multi_ids.

Records come in file order (multi_ids interleaved as logged), each decoded on its own, through
the generated reader's streaming API (``read(path, index=False)`` then ``Log.iter_records``): the
file is memory-mapped and walked once, so memory does not grow with the number of records.

Logs written before a message changed (PX4 logs of older releases) carry another format for the
topic, read through the log's own definitions: the difference is one notice per topic; fields are
matched by name (through PX4's renames, ``average_current_a`` -> ``current_average_a``), values of
another but compatible type are converted with a range check (``int32 cell_count`` -> uint8,
``float[10] voltage_cell_v`` -> float[14]), and the log's values the schema has no field for
(``voltage_filtered_v``, ``run_time_to_empty``...) travel with each record as its ``extras``. The
checks of the fields the log lacks or types incompatibly are not reported (their values would be
the schema's defaults, not the log's data) -- with one notice naming them; a value that does not
fit its converted field is one notice per record.
Damage the reader recovered from and a log without the message's topics are told after the
records, once the walk has seen the whole file.
"""

from __future__ import annotations

import contextlib
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from ...errors import cannot_read
from ..files.held import held, whole
from ..model import FormatDiff, GeneratedMessage, MessageClass, UorbClass, ulog_runtime
from ..records import InputError, Item, Notice, Record, Unreadable

MAX_DAMAGE_NOTICES = 10


@dataclass(frozen=True)
class LogRecord:
    """One decoded record: topic, instance, file offset of its 'D' record, timestamp (us)."""

    topic: str
    multi_id: int
    offset: int
    timestamp: int | None
    instance: GeneratedMessage
    skip: frozenset[str]
    extras: Mapping[str, object]
    unfit: tuple[str, ...]

    def where(self) -> str:
        stamp = f", timestamp {self.timestamp} us" if self.timestamp is not None else ""
        return f"{self.topic} multi_id {self.multi_id}{stamp}, offset {self.offset}"

    def location(self) -> dict[str, object]:
        return {"topic": self.topic, "multi_id": self.multi_id, "timestamp_us": self.timestamp, "offset": self.offset}


def _diff_line(diff: FormatDiff) -> str:
    parts = []
    if diff.missing:
        parts.append("missing from the log: " + ", ".join(f"{n} {t}" for n, t in diff.missing))
    if diff.extra:
        parts.append("only in the log: " + ", ".join(f"{n} {t}" for n, t in diff.extra))
    if diff.renamed:
        parts.append("renamed since: " + ", ".join(f"{a} -> {b}" for a, b in diff.renamed))
    if diff.converted:
        parts.append("converted: " + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in diff.converted))
    if diff.retyped:
        parts.append("retyped: " + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in diff.retyped))
    body = "; ".join(parts) if parts else "same fields, other layout"
    return f"{diff.topic}: the log's format differs from the schema's ({diff.message}): {body}"


class UlogReader:
    """An opened log and the topics of one generated uORB class; close() releases the file.

    ``notices`` holds what the definitions tell (format differences, unchecked fields) when the
    reader is made; ``trailing`` what only a whole walk can tell (damage, no records), once
    records() is exhausted.
    """

    def __init__(self, source: Path | IO[bytes], name: str, model: MessageClass) -> None:
        self.name = name
        self.model = model
        self.ulog = ulog_runtime(model)
        self._hold = contextlib.ExitStack()  # the file held still while it is read (.held_file)
        data: Path | IO[bytes] | bytes = source
        try:
            if isinstance(source, Path):
                _check_file(source, name)
                if not self._hold.enter_context(held(source, name)).leased:
                    data = whole(source, name)  # unheld, a map could end in SIGBUS
            self.log = self.ulog.read(data, index=False, warn=False)  # damage: listed in Log.warnings
        except OSError as exc:
            self._hold.close()
            raise InputError(name, 0, cannot_read(exc)) from None
        except (ValueError, struct.error, IndexError) as exc:  # ULogError is a ValueError
            self._hold.close()
            raise InputError(name, 0, f"expected a ULog file: {exc}") from None
        except BaseException:
            self._hold.close()
            raise
        topics = model.UORB_TOPICS if isinstance(model, UorbClass) else ()
        self.topics = tuple(topics or (self.ulog.format_of(model).name,))
        self.notices: list[Notice] = []
        self.trailing: list[Notice] = []  # filled once records() has walked the whole log
        self.skips: dict[str, frozenset[str]] = {}  # decodable topics -> fields left unchecked
        self._prepare()

    def close(self) -> None:
        try:
            self.log.close()
        finally:
            self._hold.close()

    def _prepare(self) -> None:
        for topic in self.topics:
            if topic not in self.log.formats:
                continue
            try:
                diff = self.log.compare(self.model, topic=topic)
                self.log.layout(topic)
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
            self.skips[topic] = skip

    def records(self) -> Iterator[LogRecord | Unreadable]:
        """Every record of the class's topics in file order (multi_ids interleaved); at the end,
        fills ``trailing``."""
        skips = self.skips
        try:
            for rec in self.log.iter_records(self.model, topic=list(skips)):
                skip = skips[rec.topic]
                stamp = (
                    getattr(rec.instance, "timestamp", None) if "timestamp" not in skip else None
                )  # not every topic has one
                yield LogRecord(
                    rec.topic,
                    rec.multi_id,
                    rec.offset,
                    stamp if isinstance(stamp, int) else None,
                    rec.instance,
                    skip,
                    rec.extras,
                    rec.unfit,
                )
        except ValueError as exc:  # a record that cannot be decoded ends the walk
            yield Unreadable(self.name, 0, str(exc))
            return
        self.trailing = self.after_walk()

    def after_walk(self) -> list[Notice]:
        """The notices a finished walk leaves (damage recovered from, topics missing), also for a reader whose
        records were read another way (the battery view's columns)."""
        out: list[Notice] = []
        problems = self.log.warnings
        for text in problems[:MAX_DAMAGE_NOTICES]:
            out.append(Notice(self.name, f"damaged log, recovered: {text}", "damage"))
        if len(problems) > MAX_DAMAGE_NOTICES:
            more = len(problems) - MAX_DAMAGE_NOTICES
            out.append(Notice(self.name, f"damaged log: {more} more problems recovered from", "damage"))
        present = sorted({t for t, _ in self.log.topics()})  # counted by the walk just finished
        if not any(t in self.skips for t in present):
            logged = ", ".join(present) or "none"
            what = " or ".join(self.topics)
            out.append(Notice(self.name, f"no {what} records in this log (topics logged: {logged})", "empty"))
        return out


def _check_file(path: Path, name: str) -> None:
    try:
        if path.is_file() and path.stat().st_size == 0:
            raise InputError(name, 0, "empty file: expected a ULog file")
    except OSError as exc:
        raise InputError(name, 0, cannot_read(exc)) from None


def ulog_items(source: Path | IO[bytes], name: str, model: MessageClass) -> Iterator[Item]:
    """The records of a .ulg file: notices first, then one record per logged message, then the
    notices of the whole walk (damage recovered from, no records of the message)."""
    reader = UlogReader(source, name, model)  # raises InputError before the first item
    return _items(reader)


def _items(reader: UlogReader) -> Iterator[Item]:
    try:
        yield from reader.notices
        index = 0
        for rec in reader.records():
            if isinstance(rec, Unreadable):
                yield rec
                continue
            if rec.unfit:
                values = ", ".join(f"{n} = {rec.extras[n]!r}" for n in rec.unfit)
                yield Notice(
                    reader.name,
                    f"{rec.where()}: does not fit the schema's type, left at its default: {values}",
                    "unfit",
                    data={**rec.location(), "fields": {n: rec.extras[n] for n in rec.unfit}},
                )
            yield Record(
                index,
                0,
                None,
                reader.name,
                where=rec.where(),
                instance=rec.instance,
                skip=rec.skip,
                location=rec.location(),
                extras=rec.extras,
            )
            index += 1
        yield from reader.trailing
    finally:
        reader.close()
