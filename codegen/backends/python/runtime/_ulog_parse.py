"""Reading a ULog file's records: the header, the definitions section and walks of the data
section, each record filling the attributes of a log (:class:`LogParser`, the base of
``_ulog.Log``, which adds the queries). Part of the ULog runtime that ``_ulog`` re-exports.

A faster walker of the data section (battgen's compiled one) drives a walk through the public
walking API: :attr:`LogParser.segments` says where the data section's records are, and
:meth:`LogParser.step` handles any one record (:meth:`LogParser.walk`, a run of them) by this
reader's rules; :attr:`LogParser.streams` holds each topic instance's record offsets and
:meth:`LogParser.bindings` which stream each msg_id's data records go to, with the record sizes
accepted. ``Log.begin_walk`` and ``Log.end_walk`` start and finish such a walk.
"""

from __future__ import annotations

import dataclasses
import mmap
import struct
import warnings
from collections.abc import Iterator
from typing import Any, ClassVar, NamedTuple

from . import _uorb
from ._ulog_format import (
    HEAD,
    INCOMPAT_DATA_APPENDED,
    MAGIC,
    SYNC,
    TYPES,
    U16,
    U64,
    Format,
    Layout,
    ULogError,
    ULogWarning,
    layout,
    parse_format,
)

Buffer = bytes | mmap.mmap  # a log's data: the file's bytes or a read-only map of it

_HEAD_ID = struct.Struct("<HBH")
# The record types this reader knows; a record of another type is skipped, unless its size is 0 or
# over MAX_UNKNOWN_SIZE: then its header is taken for corruption and the walk resynchronises.
KNOWN_TYPES = frozenset(b"ABCDFILMOPQRS")
MAX_UNKNOWN_SIZE = 10000


@dataclasses.dataclass(frozen=True)
class Subscription:
    msg_id: int
    multi_id: int
    topic: str


class Stream:
    """The records of one (topic, multi_id): where their payloads start, and the topic's layout.

    Indexed, ``offsets`` holds every record; a walk without an index holds one window's records
    there at a time and adds them to ``done`` when it moves on.
    """

    __slots__ = ("done", "key", "layout", "offsets")

    def __init__(self, key: tuple[str, int], lay: Layout | None) -> None:
        self.key = key
        self.layout = lay
        self.offsets: list[int] = []
        self.done = 0

    @property
    def total(self) -> int:
        return self.done + len(self.offsets)


class Binding(NamedTuple):
    """Where a msg_id's data records go (its latest subscription): the stream, and the record
    sizes accepted (``lo <= size <= hi``, the size field of a 'D' record, msg_id included)."""

    stream: Stream
    lo: int
    hi: int


# The attributes records change; the definitions section's values are kept, and each walk of
# the data section starts from a copy of them, so a walk can be repeated or abandoned.
WALK_STATE = (
    "formats", "info", "info_multiple", "parameters", "changed_parameters", "default_parameters", "subscriptions",
    "logged", "logged_tagged", "dropouts", "sync_count", "skipped_records", "unknown_types", "warnings",
    "_streams", "_layouts", "_column_sets", "_by_id", "_bad_ids", "_in_data",
)  # fmt: skip
_DEFINITIONS = frozenset(b"FIMPQ")  # record types that may make up the definitions section


def copy_state(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: copy_state(v) for k, v in value.items()}
    if isinstance(value, list):
        return [copy_state(v) for v in value]
    if isinstance(value, set):
        return set(value)
    return value


class LogParser:
    """A ULog file's data and what its records say; :class:`_ulog.Log` adds the queries.

    ``data`` is the file: bytes, or a read-only memory map.
    """

    def __init__(self, data: Buffer, *, warn: bool = True) -> None:
        self.data = data
        self.warn = warn  # issue a ULogWarning for each problem, besides listing it in ``warnings``
        self.version = 0
        self.timestamp = 0
        self.compat_flags = bytes(8)
        self.incompat_flags = bytes(8)
        self.appended_offsets: tuple[int, ...] = ()
        self.formats: dict[str, Format] = {}
        self.info: dict[str, Any] = {}
        self.info_multiple: dict[str, list[list[Any]]] = {}
        self.parameters: dict[str, Any] = {}  # initial values (definitions section)
        self.changed_parameters: list[tuple[str, Any]] = []  # set while logging, in order
        self.default_parameters: dict[str, tuple[int, Any]] = {}  # name -> (default type bits, value)
        self.subscriptions: list[Subscription] = []
        self.logged: list[tuple[int, int, str]] = []  # (level, timestamp, text)
        self.logged_tagged: list[tuple[int, int, int, str]] = []  # (tag, level, timestamp, text)
        self.dropouts: list[int] = []  # durations in ms
        self.sync_count = 0
        self.skipped_records = 0  # data records dropped as damaged
        self.unknown_types: dict[str, int] = {}  # record types this reader skipped, with counts
        self.warnings: list[str] = []
        self._streams: dict[tuple[str, int], Stream] = {}
        self._layouts: dict[str, Layout] = {}
        self._column_sets: dict[str, _uorb.Columns] = {}
        # msg_id -> (stream.offsets.append, min and max record size, stream): the walk's hot path reads it
        self._by_id: dict[int, tuple[Any, int, int, Stream]] = {}
        self._bad_ids: set[int] = set()  # ids warned about (once each)
        self._in_data = False
        self._segments: list[tuple[int, int]] = []  # data section: (start, stop) up to each appended offset
        self._definitions: dict[str, Any] = {}  # WALK_STATE as the definitions section left it
        self.walked = False  # a walk of the data section finished: the attributes above are complete
        self.indexed = False  # ... and it kept every record's offset

    KNOWN_TYPES: ClassVar[frozenset[int]] = KNOWN_TYPES

    # -- the walking API ---------------------------------------------------------------------

    @property
    def segments(self) -> list[tuple[int, int]]:
        """The data section's records: (start, stop) byte ranges, one up to each appended-data offset."""
        return list(self._segments)

    @property
    def streams(self) -> dict[tuple[str, int], Stream]:
        """The record offsets of every topic instance, by (topic, multi_id), as walks fill them."""
        return self._streams

    def bindings(self) -> dict[int, Binding]:
        """Which stream each msg_id's data records go to now (as the walk has got so far)."""
        return {msg_id: Binding(e[3], e[1], e[2]) for msg_id, e in self._by_id.items()}

    def binding(self, msg_id: int) -> Binding | None:
        """Where data records of ``msg_id`` go now, or None (not subscribed: they are skipped)."""
        e = self._by_id.get(msg_id)
        return Binding(e[3], e[1], e[2]) if e is not None else None

    def layout(self, topic: str) -> Layout:
        """The log's own layout of a topic."""
        lay = self._layouts.get(topic)
        if lay is None:
            fmt = self.formats.get(topic)
            if fmt is None:
                raise ULogError(f"no format for topic {topic!r} in this log")
            lay = self._layouts[topic] = layout(fmt, self.formats)
        return lay

    def _columns(self, topic: str) -> _uorb.Columns:
        cols = self._column_sets.get(topic)
        if cols is None:
            cols = self._column_sets[topic] = self.layout(topic).columns()
        return cols

    def _warn(self, text: str) -> None:
        self.warnings.append(text)
        if self.warn:
            warnings.warn(text, ULogWarning, stacklevel=2)

    def _load(self) -> None:
        """Read the header and the definitions section."""
        data = self.data
        if len(data) < 16 or data[:7] != MAGIC:
            raise ULogError("not a ULog file: expected the magic bytes 'ULog' 01 12 35 and a 16-byte header")
        self.version = data[7]
        self.timestamp = U64.unpack_from(data, 8)[0]
        pos, end = 16, len(data)
        starts = [pos]
        if end >= 19:
            size, kind = HEAD.unpack_from(data, pos)
            if kind == ord("B") and pos + 3 + size <= end:
                self._flag_bits(data[pos + 3 : pos + 3 + size])
                starts = [pos + 3 + size]
                if self.incompat_flags[0] & INCOMPAT_DATA_APPENDED:
                    good = sorted(o for o in self.appended_offsets if starts[0] < o <= end)
                    if len(good) != len(self.appended_offsets):
                        self._warn(f"ignored appended-data offsets outside the file: {self.appended_offsets}")
                    starts += good
        self._segments = [(start, starts[i + 1] if i + 1 < len(starts) else end) for i, start in enumerate(starts)]
        # The definitions section: formats, info and parameters up to the first record of another kind
        # (damage included: the data section's walk reports it).
        pos, stop = self._segments[0]
        while pos + 3 <= stop:
            size, kind = HEAD.unpack_from(data, pos)
            if kind not in _DEFINITIONS or pos + 3 + size > stop:
                break
            pos = self.step(pos, size, kind, stop, stop == end)
        self._segments[0] = (pos, stop)
        self._definitions = {name: copy_state(getattr(self, name)) for name in WALK_STATE}

    def _flag_bits(self, body: bytes) -> None:
        if len(body) < 40:
            self._warn(f"flag bits record of {len(body)} bytes, expected 40")
            body = body + bytes(40 - len(body))
        self.compat_flags = bytes(body[:8])
        self.incompat_flags = bytes(body[8:16])
        self.appended_offsets = tuple(o for o in struct.unpack_from("<3Q", body, 16) if o)
        if self.incompat_flags[0] & ~INCOMPAT_DATA_APPENDED or any(self.incompat_flags[1:]):
            raise ULogError(f"unknown incompatible flag bits {self.incompat_flags.hex()}: cannot read this log")

    def _windows(self, size: int) -> Iterator[None]:
        """Walk the data section, pausing after the records that start in each ``size`` bytes."""
        end = len(self.data)
        for start, stop in self._segments:
            pos = start
            while pos <= stop:
                pos = self.walk(pos, stop, stop == end, pos + size)
                yield

    def walk(self, pos: int, end: int, at_eof: bool, limit: int) -> int:
        """Handle the records from ``pos`` that start before ``limit``, in the segment ending at
        ``end`` (``at_eof``: the file's end, not an appended-data offset): where the next one
        starts, or ``end + 1`` once the segment is done."""
        data = self.data
        head = _HEAD_ID.unpack_from  # size, type and (for 'D') msg_id in one call
        by_id = self._by_id
        stop = min(limit, end - 4)  # a 'D' header and msg_id are 5 bytes
        while pos < stop:
            size, kind, msg_id = head(data, pos)
            nxt = pos + 3 + size
            if kind == 68 and nxt <= end:  # 'D', by far the most frequent: keep this path short
                entry = by_id.get(msg_id)
                if entry is not None and entry[1] <= size <= entry[2]:
                    entry[0](pos + 5)
                else:
                    self._bad_data(msg_id, size - 2, pos)
                pos = nxt
                continue
            pos = self.step(pos, size, kind, end, at_eof)
        if pos < end - 4:
            return pos  # paused at the window's end
        while pos + 3 <= end:  # records of under 2 bytes at the very end
            size, kind = HEAD.unpack_from(data, pos)
            pos = self.step(pos, size, kind, end, at_eof)
        if pos < end and at_eof:
            self._warn(f"truncated record header at offset {pos}: {end - pos} bytes at the end of the file")
        return end + 1

    def step(self, pos: int, size: int, kind: int, end: int, at_eof: bool) -> int:
        """Handle the record at ``pos`` (any type; ``size`` and ``kind`` read from its header) in
        the segment ending at ``end``: the next record's position, or one past ``end`` to stop."""
        nxt = pos + 3 + size
        if nxt > end:
            where = "at the end of the file" if at_eof else "before an appended-data offset"
            self._warn(f"truncated record {chr(kind)!r} at offset {pos}: {end - pos - 3} of {size} bytes {where}")
            return end + 1
        if kind == 0 or (kind not in KNOWN_TYPES and (size == 0 or size > MAX_UNKNOWN_SIZE)):
            resync = self.data.find(SYNC, pos + 1, end)
            self._warn(f"corrupt record header at offset {pos}" + ("" if resync < 0 else f", resynced at {resync}"))
            return end + 1 if resync < 0 else resync + len(SYNC)
        if kind == 68:
            if size < 2:
                self._bad_data(-1, size - 2, pos)
            else:
                msg_id = U16.unpack_from(self.data, pos + 3)[0]
                entry = self._by_id.get(msg_id)
                if entry is not None and entry[1] <= size <= entry[2]:
                    entry[0](pos + 5)
                else:
                    self._bad_data(msg_id, size - 2, pos)
            return nxt
        try:
            self._other(kind, self.data[pos + 3 : nxt], pos)
        except (ULogError, UnicodeDecodeError, struct.error, ValueError, IndexError) as exc:
            self._warn(f"skipped a bad {chr(kind)!r} record at offset {pos}: {exc}")
        return nxt

    def _bad_data(self, msg_id: int, size: int, pos: int) -> None:
        self.skipped_records += 1
        if msg_id in self._bad_ids:
            return
        self._bad_ids.add(msg_id)
        entry = self._by_id.get(msg_id)
        if entry is None:
            self._warn(f"data for msg_id {msg_id} without a subscription (first at offset {pos}), skipped")
        else:
            self._warn(f"data of {size} bytes for msg_id {msg_id} at offset {pos}, expected {entry[1] - 2}, skipped")

    def _other(self, kind: int, body: bytes, pos: int) -> None:
        if kind == 65:  # 'A' subscription
            multi_id, msg_id = struct.unpack_from("<BH", body)
            topic = body[3:].decode("utf-8", "replace").rstrip("\0")
            self._in_data = True
            self.subscriptions.append(Subscription(msg_id, multi_id, topic))
            stream = self._streams.get((topic, multi_id))
            if stream is None:
                lay = None
                try:
                    lay = self.layout(topic)
                except ULogError as exc:
                    self._warn(f"subscription to {topic!r} (msg_id {msg_id}): {exc}")
                stream = self._streams[(topic, multi_id)] = Stream((topic, multi_id), lay)
            lo, hi = (stream.layout.data_size, stream.layout.size) if stream.layout else (0, 0xFFFD)
            self._by_id[msg_id] = (stream.offsets.append, lo + 2, hi + 2, stream)  # record sizes: msg_id included
            self._bad_ids.discard(msg_id)
        elif kind == 82:  # 'R' unsubscribe
            self._by_id.pop(U16.unpack_from(body)[0], None)
        elif kind == 70:  # 'F' format
            fmt = parse_format(body.decode("utf-8"))
            self.formats[fmt.name] = fmt
            self._layouts.clear()  # a late (re)definition: recompute layouts on demand
            self._column_sets.clear()
        elif kind == 73:  # 'I' info
            key, value = _key_value(body)
            self.info[key] = value
        elif kind == 77:  # 'M' multi-part info
            key, value = _key_value(body[1:])
            parts = self.info_multiple.setdefault(key, [])
            if body[0] and parts:
                parts[-1].append(value)
            else:
                parts.append([value])
        elif kind == 80:  # 'P' parameter
            key, value = _key_value(body)
            if self._in_data:
                self.changed_parameters.append((key, value))
            else:
                self.parameters[key] = value
        elif kind == 81:  # 'Q' default parameter
            key, value = _key_value(body[1:])
            self.default_parameters[key] = (body[0], value)
        elif kind == 76:  # 'L' logged text
            level, stamp = struct.unpack_from("<BQ", body)
            self.logged.append((level, stamp, body[9:].decode("utf-8", "replace")))
            self._in_data = True
        elif kind == 67:  # 'C' tagged logged text
            level, tag, stamp = struct.unpack_from("<BHQ", body)
            self.logged_tagged.append((tag, level, stamp, body[11:].decode("utf-8", "replace")))
            self._in_data = True
        elif kind == 79:  # 'O' dropout
            self.dropouts.append(U16.unpack_from(body)[0])
        elif kind == 83:  # 'S' sync
            self.sync_count += 1
        elif kind == 66:  # 'B' flag bits: only valid first
            self._warn(f"flag bits record at offset {pos}, expected only as the first record")
        else:
            name = chr(kind)
            self.unknown_types[name] = self.unknown_types.get(name, 0) + 1


def _key_value(body: bytes) -> tuple[str, Any]:
    """The key and typed value of an 'I', 'M', 'P' or 'Q' body (from its key_len byte)."""
    n = body[0]
    type_text, _, key = body[1 : 1 + n].decode("utf-8", "replace").partition(" ")
    raw = body[1 + n :]
    ctype, _, count = type_text.partition("[")
    if ctype == "char":
        return key, raw.decode("utf-8", "replace").rstrip("\0")
    known = TYPES.get(ctype)
    if known is None or (ctype == "uint8_t" and count):  # uint8_t[N]: bytes, as for message fields
        return key, bytes(raw)
    code, width, _ = known
    if not count:
        return key, struct.unpack("<" + code, raw[:width])[0] if len(raw) >= width else bytes(raw)
    digits = count.rstrip("]")
    n_items = int(digits) if digits.isascii() and digits.isdigit() else 0
    if len(raw) < n_items * width:
        return key, bytes(raw)
    return key, list(struct.unpack_from(f"<{n_items}{code}", raw))
