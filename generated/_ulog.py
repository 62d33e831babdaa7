# Copied by battgen from codegen/backends/python/runtime/_ulog.py; do not edit here, edit it there.
"""ULog, the PX4 log format: write generated uORB messages into a log and read logs back.

A ULog file is a 16-byte header (magic, version, start timestamp in microseconds) and a stream
of records, each ``uint16 size, uint8 type`` then ``size`` bytes. The definitions section holds
flag bits ('B', first), formats ('F': ``name:type field;...``), info ('I', 'M') and parameters
('P', 'Q'); the data section holds subscriptions ('A': multi_id, msg_id, topic), data ('D':
msg_id then the struct without its trailing padding), log text ('L', 'C'), syncs and dropouts.

Generated uORB classes describe themselves with ``ulog_format()``; this module writes them
(:class:`Writer`, :func:`write`), reads any log (:func:`read` -> :class:`Log`), and compares a
log's own format with a class's (:class:`FormatDiff`), decoding the fields that match. Standard
library only. Its parts: ``_ulog_format`` (constants, formats, layouts), ``_ulog_compare`` (log
format vs class), ``_ulog_writer`` and ``_ulog_parse`` (reading records); their public names are
importable from here.

Reading::

    log = read(path)                        # a path is memory-mapped (mmap=False reads it whole);
                                            # bytes and binary files are accepted too
    log.topics(), log.count(topic, multi_id), log.info, log.parameters, log.logged, log.warnings
    log.compare(BatteryStatus)              # FormatDiff: .missing / .retyped fields keep defaults
    log.messages(BatteryStatus)             # one topic instance as a list
    log.columns("battery_status")           # values as columns (numpy if installed)
    for rec in log.iter_records(BatteryStatus):   # Record(offset, multi_id, topic, instance)
        ...                                 # every topic and instance of the class, in file order

``read(path, index=False)`` reads only the header and the definitions section; each
``iter_records`` then walks the data section once, holding one window of offsets at a time, so a
log of any length is streamed in constant memory. Queries that need every offset (``messages``,
``columns``, ``records``) index such a log on first use; the attributes the data section fills
(``subscriptions``, ``logged``, ``warnings``...) are complete once a walk has finished
(``Log.walked``). ``Record.offset`` is where the record's 'D' header starts in the file.

Another walker of the data section (battgen's compiled index) works through the public walking
API: ``Log.begin_walk`` / ``Log.end_walk`` around a walk that hands each record it cannot decide
to ``Log.step`` (see ``_ulog_parse``); ``Log.index()`` and ``Log.decoder()`` are what the queries
above use.
"""

from __future__ import annotations

import copy
import heapq
import mmap
import os
import struct
from collections.abc import Callable, Iterable, Iterator, Mapping
from itertools import repeat
from typing import Any, BinaryIO, Generic, NamedTuple, TypeVar

from . import _uorb
from ._ulog_compare import (
    EMPTY,
    RENAMED,
    FormatDiff,
    Retyped,
    compare,
    convert,
    convert_plan,
    extra_indexes,
    fill,
    fill_plan,
)
from ._ulog_format import (
    COMPAT_DEFAULT_PARAMETERS,
    INCOMPAT_DATA_APPENDED,
    MAGIC,
    SYNC,
    TYPES,
    VERSION,
    Format,
    Layout,
    Member,
    ULogError,
    ULogWarning,
    format_of,
    layout,
    parse_format,
)
from ._ulog_parse import (
    KNOWN_TYPES,
    MAX_UNKNOWN_SIZE,
    WALK_STATE,
    Binding,
    Buffer,
    LogParser,
    Stream,
    Subscription,
    copy_state,
)
from ._ulog_writer import Writer, write

__all__ = [
    "COMPAT_DEFAULT_PARAMETERS",
    "INCOMPAT_DATA_APPENDED",
    "KNOWN_TYPES",
    "MAGIC",
    "MAX_UNKNOWN_SIZE",
    "RENAMED",
    "SYNC",
    "TYPES",
    "VERSION",
    "Binding",
    "Buffer",
    "Decoder",
    "Format",
    "FormatDiff",
    "Layout",
    "Log",
    "Member",
    "Record",
    "Retyped",
    "Source",
    "Stream",
    "Subscription",
    "ULogError",
    "ULogWarning",
    "Writer",
    "compare",
    "format_of",
    "layout",
    "parse_format",
    "read",
    "write",
]

T = TypeVar("T")

Source = str | os.PathLike[str] | bytes | bytearray | memoryview | mmap.mmap | BinaryIO
_MAP = mmap.mmap  # read() has a parameter named mmap


class Record(NamedTuple, Generic[T]):
    """One data record of :meth:`Log.iter_records`, decoded.

    ``extras``: the log's values the instance does not hold, by the log's flattened name (fields
    the class lacks, array elements beyond its length, values out of its type's range); ``unfit``
    names those of them that did not fit the class's type (the field keeps its default)."""

    offset: int  # where the 'D' record starts in the file (its size field)
    multi_id: int
    topic: str
    instance: T
    extras: Mapping[str, Any] = EMPTY
    unfit: tuple[str, ...] = ()


Decoder = Callable[[int], tuple[T, Mapping[str, Any], tuple[str, ...]]]
_WINDOW = 1 << 18  # bytes of data section a walk without an index reads between handing out records
_D_HEAD = 5  # uint16 size, uint8 'D', uint16 msg_id: a record's payload starts this far in


def _first(pair: tuple[int, Stream]) -> int:
    return pair[0]


class Log(LogParser):
    """A ULog file: its definitions read, its data section indexed (offsets of the records of
    every topic instance) or, from ``read(..., index=False)``, walked when asked for.

    ``data`` is the file: bytes, or a read-only memory map (close() or ``with`` releases it).
    """

    def __enter__(self) -> Log:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Release a memory-mapped file (queries fail afterwards); nothing to do for bytes."""
        if isinstance(self.data, mmap.mmap):
            try:
                self.data.close()
            except BufferError:  # a view into the map is still alive: the map goes with the last one
                pass

    # -- queries --------------------------------------------------------------------------------

    def topics(self) -> list[tuple[str, int]]:
        """(topic, multi_id) of every subscription with at least one record."""
        self._count()
        return sorted(k for k, s in self._streams.items() if s.total)

    def count(self, topic: str, multi_id: int = 0) -> int:
        self._count()
        stream = self._streams.get((topic, multi_id))
        return stream.total if stream else 0

    def records(self, topic: str, multi_id: int = 0) -> bytes:
        """Every record of a topic instance back to back, each ``layout(topic).data_size`` bytes."""
        size = self.layout(topic).data_size
        stream = self.index().get((topic, multi_id))
        if stream is None or not stream.offsets:
            return b""
        view = memoryview(self.data)
        return b"".join([view[o : o + size] for o in stream.offsets])

    def columns(self, topic: str, multi_id: int = 0, *, use_numpy: bool | None = None) -> dict[str, Any]:
        """Every value of a topic instance as columns named from the log's format (``a[0]``,
        ``b.c``; char arrays as bytes; padding skipped): numpy arrays if installed (``use_numpy``
        None) or required (True), else lists."""
        size = self.layout(topic).data_size
        np = _uorb.numpy_module(use_numpy)
        stream = self.index().get((topic, multi_id))
        if np is not None and stream is not None and stream.offsets:
            # Gather the records with one fancy-indexing step: a view of the file holding a
            # size-byte record at every byte offset, indexed by the records' offsets.
            at_every_byte = np.ndarray(
                buffer=self.data, dtype=np.dtype((np.void, size)), shape=(len(self.data) - size + 1,), strides=(1,)
            )
            packed = at_every_byte[np.asarray(stream.offsets, dtype=np.intp)].view(np.uint8)
            return self._columns(topic).decode(packed, size, use_numpy=True)
        return self._columns(topic).decode(self.records(topic, multi_id), size, use_numpy=False)

    def compare(self, cls: type[Any], *, topic: str | None = None) -> FormatDiff:
        """How this log's format for ``topic`` differs from generated class ``cls``."""
        topic = topic or _default_topic(cls)
        fmt = self.formats.get(topic)
        if fmt is None:
            raise ULogError(f"no format for topic {topic!r} in this log")
        return compare(cls, fmt, self.formats, topic)

    def messages(self, cls: type[T], *, topic: str | None = None, multi_id: int = 0) -> list[T]:
        """Every record of a topic instance as ``cls`` instances. With the class's own layout each
        record goes through ``cls.decode``; otherwise fields matching by name and type are filled
        and the others keep their defaults (see :meth:`compare`)."""
        topic = topic or _default_topic(cls)
        decode = self.decoder(cls, topic)
        stream = self.index().get((topic, multi_id))
        return [decode(o)[0] for o in stream.offsets] if stream is not None else []

    def iter_records(
        self, cls: type[T], *, topic: str | Iterable[str] | None = None, multi_id: int | None = None
    ) -> Iterator[Record[T]]:
        """The records of ``cls``'s topics one at a time, in file order (instances interleaved as
        logged), decoded as :meth:`messages` does: fields the log lacks or types otherwise keep
        their defaults (:meth:`compare` names them).

        ``topic``: one topic or several; None takes every topic of the class that the log has a
        format for. ``multi_id``: one instance, or None for all. An indexed log hands out its
        index; otherwise the data section is walked once, in constant memory. A topic without a
        format in the log raises ULogError here, before the first record.
        """
        if topic is None:
            fmt = format_of(cls)
            names = [t for t in fmt.topics or (fmt.name,) if t in self.formats]
        else:
            names = [topic] if isinstance(topic, str) else list(topic)
        decoders = {t: self.decoder(cls, t) for t in names}
        return self._decode_all(decoders, multi_id)

    def _decode_all(self, decoders: dict[str, Decoder[T]], multi_id: int | None) -> Iterator[Record[T]]:
        def wanted(key: tuple[str, int]) -> bool:
            return key[0] in decoders and (multi_id is None or key[1] == multi_id)

        found: Iterable[tuple[int, Stream]]
        if self.indexed:
            chosen = [zip(s.offsets, repeat(s)) for k, s in sorted(self._streams.items()) if wanted(k)]
            found = chosen[0] if len(chosen) == 1 else heapq.merge(*chosen, key=_first)
        else:
            found = self._walk_unindexed(wanted)
        for offset, stream in found:
            topic, multi_id_ = stream.key
            try:
                obj, extras, unfit = decoders[topic](offset)
            except (ValueError, struct.error) as exc:
                at = offset - _D_HEAD
                raise ULogError(f"{topic} multi_id {multi_id_}, record at offset {at}: cannot decode: {exc}") from exc
            yield Record(offset - _D_HEAD, multi_id_, topic, obj, extras, unfit)

    def decoder(self, cls: type[T], topic: str) -> Decoder[T]:
        """What :meth:`messages` and :meth:`iter_records` decode each record of ``topic`` with: from
        the offset of a record's payload, the ``cls`` instance, the log's values it does not hold,
        and which of them did not fit (see :class:`Record`)."""
        diff = self.compare(cls, topic=topic)
        data, size = self.data, self.layout(topic).data_size
        if diff.identical:
            decode: Callable[[bytes], T] = getattr(cls, "decode")  # noqa: B009 (the generated classmethod, unknown to T)
            return lambda o: (decode(data[o : o + size]), EMPTY, ())
        unpack = self._columns(topic).record_struct(size).unpack_from
        names = self.layout(topic).names
        skip = {name for name, _ in diff.missing} | {r.name for r in diff.retyped} | {r.name for r in diff.converted}
        alias = {new: old for old, new in diff.renamed}
        ours = format_of(cls)
        plan = fill_plan(ours, {n: i for i, n in enumerate(names)}, "", "", skip, alias)
        conversions = convert_plan(ours, diff.converted, alias, names)
        extra_at = extra_indexes(diff.extra, names)

        def decode_other(o: int) -> tuple[T, Mapping[str, Any], tuple[str, ...]]:
            values = unpack(data, o)
            obj = fill(cls(), plan, values)
            extras = {name: values[i] for i, name in extra_at}
            unfit = convert(obj, conversions, values, extras)
            return obj, extras or EMPTY, tuple(unfit)

        return decode_other

    # -- walking the data section ---------------------------------------------------------------

    def index(self) -> dict[tuple[str, int], Stream]:
        """Every record's offset by (topic, multi_id), walking the data section if not done yet."""
        if not self.indexed:
            walk = self._fresh()
            for _ in walk._windows(len(self.data) + 1):
                pass
            self._adopt(walk, indexed=True)
        return self._streams

    def _count(self) -> None:
        if not self.walked:
            for _ in self._walk_unindexed(lambda key: False):
                pass

    def _walk_unindexed(self, wanted: Callable[[tuple[str, int]], bool]) -> Iterator[tuple[int, Stream]]:
        """(payload offset, stream) of the wanted streams' records in file order, walking the data
        section a window at a time (only a window's offsets are held). A walk that finishes makes
        its results (subscriptions, counts, warnings...) this log's."""
        walk = self._fresh()
        for _ in walk._windows(_WINDOW):
            streams = [s for s in walk._streams.values() if s.offsets]
            chosen = [s for s in streams if wanted(s.key)]
            if len(chosen) == 1:
                yield from zip(chosen[0].offsets, repeat(chosen[0]))
            elif chosen:
                yield from sorted([(o, s) for s in chosen for o in s.offsets], key=_first)
            for s in streams:
                s.done += len(s.offsets)
                s.offsets.clear()
        self._adopt(walk, indexed=False)

    def begin_walk(self) -> Log:
        """A log to walk the data section with (:meth:`step`, :meth:`walk`) from the state the
        definitions section left: this log itself if its data section was never walked (nothing to
        copy), else a fresh copy. :meth:`end_walk` makes a finished walk's results this log's; an
        abandoned walk can be left as it is (each walk starts from the definitions' state)."""
        return self if not self.walked else self._fresh()

    def end_walk(self, walk: Log, *, indexed: bool) -> None:
        """Make a finished walk from :meth:`begin_walk` this log's: its subscriptions, counts,
        warnings...; ``indexed``: the walk kept every record's offset in its streams."""
        self._adopt(walk, indexed=indexed)

    def _fresh(self) -> Log:
        """A copy of this log as its definitions section left it, to walk the data section with."""
        walk = copy.copy(self)
        for name, value in self._definitions.items():
            setattr(walk, name, copy_state(value))
        return walk

    def _adopt(self, walk: Log, *, indexed: bool) -> None:
        if walk is not self:
            for name in WALK_STATE:
                setattr(self, name, getattr(walk, name))
        self.walked = True
        self.indexed = indexed


def _default_topic(cls: type[Any]) -> str:
    fmt = format_of(cls)
    return fmt.topics[0] if fmt.topics else fmt.name


def read(source: Source, *, mmap: bool = True, index: bool = True, warn: bool = True) -> Log:
    """Read a ULog file: a path (memory-mapped unless ``mmap`` is False), bytes, a memory map (used
    as it is, and closed with the log) or a binary file.

    With ``index`` (the default) the data section is walked at once and every record's offset
    kept; without, only the header and definitions are read, and the data section is walked by
    each :meth:`Log.iter_records` (or indexed on the first query that needs it). Damage is
    recovered from and listed in ``Log.warnings``, each issued as a :class:`ULogWarning` too
    unless ``warn`` is False; a file that is not ULog raises ULogError.
    """
    if isinstance(source, bytes):
        data: Buffer = source
    elif isinstance(source, _MAP):  # shared with the caller (who hashed it, say): no copy
        data = source
    elif isinstance(source, bytearray | memoryview):
        data = bytes(source)
    elif isinstance(source, str | os.PathLike):
        data = _open(source, mmap)
    else:
        data = source.read()
    log = Log(data, warn=warn)
    try:
        log._load()
        if index:
            log.index()
    except BaseException:
        log.close()
        raise
    return log


def _open(path: str | os.PathLike[str], use_map: bool) -> Buffer:
    with open(path, "rb") as f:
        if use_map:
            try:
                return mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
            except (OSError, ValueError):  # empty, a pipe, or a file system that cannot map: read it
                pass
        return f.read()
