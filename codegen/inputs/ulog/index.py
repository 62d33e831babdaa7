"""A ULog's record index as numpy arrays, walked at C speed: for whole-log work (``battgen export``).

The generated reader (``generated/_ulog*.py``, standard library only) walks the data section one
record at a time in Python, about 0.3 s per million records. Here the walk itself -- where each
record starts -- is done by a small C function (``_scan.c``, built at install when a compiler
is there), and what the records mean stays the generated reader's:

- every record that is not data ('A' subscriptions, 'L' text, 'P' parameters...) goes through the
  generated ``step``, in file order, so subscriptions, info, warnings and counts come out as a
  walk of the generated reader leaves them;
- the data records ('D', nearly all of a log) are sorted into their streams with numpy: each
  takes the subscription its msg_id had when it was logged, and its size is checked as the
  generated walker checks it; a log with records it would skip (damage) is left to it whole,
  since its warnings about them interleave with the others;
- where the generated walker would do something special (a record running past the end, a
  corrupt header to resynchronise after), the C walk stops and the generated ``step`` decides.

It uses only the generated reader's public walking API (:class:`.model.UlogWalk`).

Without the compiled walk, :func:`record_offsets` falls back on the generated index. Either way
the result is the same: tests/inputs/test_ulog_index.py compares the two on real, synthetic and
damaged logs.
"""

from __future__ import annotations

import itertools
import struct
from collections.abc import Callable, Sequence
from typing import Any, cast

from ..model import UlogBinding, UlogWalk

NDArray = Any  # numpy arrays
StreamKey = tuple[str, int]

_D = 68  # 'D'
_A = 65  # 'A'
_R = 82  # 'R'
_D_HEAD = 5  # uint16 size, uint8 'D', uint16 msg_id: a data record's payload starts this far in
_HEAD = struct.Struct("<HB")
_HEADS = 1 << 15  # record heads per C walk call (512 KiB)

_scan: Callable[[Any, int, int, bytes, Any], tuple[int, int]] | None
# gather(buffer, offsets, record_size, [(offset, size, out)]): fields out of records (ulog_columns)
gather: Callable[[Any, Any, int, Sequence[tuple[int, int, Any]]], None] | None
try:
    from ._scan import gather
    from ._scan import scan as _scan
except ImportError:  # no C compiler at install time: the generated walker does the work, numpy gathers
    _scan = gather = None


def compiled() -> bool:
    """Whether the C walk was built (else the generated walker indexes logs)."""
    return _scan is not None


def record_offsets(log: Any, *, use_compiled: bool | None = None) -> dict[StreamKey, NDArray]:
    """The payload offset of every record of ``log`` (a generated ``_ulog.Log`` read with
    ``index=False``) by (topic, multi_id), as int64 arrays in file order. Walking the data
    section leaves the log's subscriptions, counts and warnings as the generated walk would;
    ``use_compiled`` False (or the extension missing) takes the generated index instead."""
    import numpy as np

    typed = cast(UlogWalk, log)
    if _scan is None or use_compiled is False or typed.indexed:
        return {k: np.asarray(s.offsets, np.int64) for k, s in typed.index().items() if s.offsets}
    # A log not walked yet is walked in place (copying its definitions' state, parameters and all,
    # cost a real log some milliseconds); else a fresh copy.
    walk = typed.begin_walk()
    found: dict[StreamKey, list[NDArray]] = {}
    try:
        for start, stop in walk.segments:
            _walk_segment(walk, start, stop, found)
    except _Fallback:  # a damaged log: the generated walker (from the definitions), whose warnings come in its order
        return record_offsets(log, use_compiled=False)
    typed.end_walk(walk, indexed=False)
    return {k: parts[0] if len(parts) == 1 else np.concatenate(parts) for k, parts in found.items()}


class _Fallback(Exception):
    """Records the generated walker skips (with warnings whose order matters): let it walk."""


def _known_types(walk: UlogWalk) -> bytes:
    """The generated reader's known record types, as 256 flags for the C walk."""
    return bytes(1 if t in walk.KNOWN_TYPES else 0 for t in range(256))


def _drain(walk: UlogWalk, found: dict[StreamKey, list[NDArray]]) -> None:
    """Move the offsets the generated walker listed (in its stream lists) into ``found``, in order."""
    import numpy as np

    for key, stream in walk.streams.items():
        if stream.offsets:
            found.setdefault(key, []).append(np.asarray(stream.offsets, np.int64))
            stream.done += len(stream.offsets)
            stream.offsets.clear()


def _walk_segment(walk: UlogWalk, start: int, stop: int, found: dict[StreamKey, list[NDArray]]) -> None:
    """Walk the records in [start, stop) as the generated ``_windows`` does, the C walk first."""
    import numpy as np

    assert _scan is not None
    data, at_eof = walk.data, stop == len(walk.data)
    known = _known_types(walk)
    heads = np.empty(_HEADS, _head_dtype())  # reused: a buffer the CPU's cache holds
    bindings = _Bindings(walk)
    pos = start
    while pos < stop - 4:
        count, nxt = _scan(data, pos, stop, known, heads)
        _sort_records(walk, bindings, heads[:count], stop, at_eof, found)
        pos = nxt
        if count == len(heads):  # the buffer is full: walk on
            continue
        if nxt >= stop - 4:
            break
        size, kind = _HEAD.unpack_from(data, nxt)  # truncated or corrupt: the generated rules decide
        pos = walk.step(nxt, size, kind, stop, at_eof)
        _drain(walk, found)
    if pos <= stop:  # the last 4 bytes, and the warnings about a truncated end, as generated
        walk.walk(pos, stop, at_eof, stop + 1)
        _drain(walk, found)


def _head_dtype() -> Any:
    """The C walk's record head (``struct head`` in _scan.c), native byte order."""
    import numpy as np

    return np.dtype(
        {"names": ["pos", "size", "msg_id", "type"], "formats": ["i8", "u2", "u2", "u1"], "offsets": [0, 8, 10, 12],
         "itemsize": 16}
    )  # fmt: skip


def _sort_records(
    walk: UlogWalk,
    bindings: _Bindings,
    heads: NDArray,
    stop: int,
    at_eof: bool,
    found: dict[StreamKey, list[NDArray]],
) -> None:
    """Sort the records whose heads the C walk gave into their streams (copying what it keeps:
    the heads' buffer is reused)."""
    import numpy as np

    if not len(heads):
        return
    is_data = heads["type"] == _D
    bindings.restart()
    others = heads[~is_data]
    for pos, size, kind, msg_id in zip(  # subscriptions and the rest, in file order, through the generated reader
        others["pos"].tolist(), others["size"].tolist(), others["type"].tolist(), others["msg_id"].tolist(), strict=True
    ):
        walk.step(pos, size, kind, stop, at_eof)
        if kind == _A and size >= 3:
            bindings.event(pos, _u16_at(walk.data, pos + 4))
        elif kind == _R and size >= 2:
            bindings.event(pos, msg_id)
    data = heads[is_data] if len(others) else heads
    if not len(data):
        return
    starts, sizes, msg_ids = data["pos"], data["size"], data["msg_id"]
    binding = bindings.resolve(starts, msg_ids)
    lo, hi, stream_of = bindings.tables()
    if not ((lo[binding] <= sizes) & (sizes <= hi[binding])).all():
        raise _Fallback  # records the generated walker skips, warning in an order it alone knows
    streams = stream_of[binding]
    payloads = starts + _D_HEAD
    if len(bindings.keys) > 1:
        order = np.argsort(streams.astype(np.int16 if len(bindings.keys) < 1 << 15 else np.int64), kind="stable")
        streams, payloads = streams[order], payloads[order]
    cuts = [0, *(np.flatnonzero(np.diff(streams)) + 1).tolist(), len(streams)]
    for begin, end in itertools.pairwise(cuts):
        if end > begin:
            key = bindings.keys[int(streams[begin])]
            found.setdefault(key, []).append(payloads[begin:end])
            walk.streams[key].done += end - begin


def _u16_at(data: Any, pos: int) -> int:
    return int(data[pos]) | int(data[pos + 1]) << 8 if pos + 1 < len(data) else -1


class _Bindings:
    """Which stream each msg_id is bound to over a stretch of records: the binding before the
    stretch, then each 'A' / 'R' record's change, as the generated reader's ``bindings()`` has it."""

    def __init__(self, walk: UlogWalk) -> None:
        self.walk = walk
        self.entries: list[tuple[int, int, int]] = []  # (stream, lo, hi) of each binding seen
        self.keys: list[StreamKey] = []
        self._stream_index: dict[StreamKey, int] = {}  # stream key -> index into keys
        self._entry_index: dict[tuple[int, int, int], int] = {}
        self.initial: dict[int, int] = {}
        self.events: list[tuple[int, int, int]] = []  # (msg_id, position, binding or -1)

    def restart(self) -> None:
        """A new stretch of records: the bindings the generated reader holds now, no changes yet."""
        self.initial = {msg_id: self._binding(b) for msg_id, b in self.walk.bindings().items()}
        self.events = []

    def _binding(self, binding: UlogBinding | None) -> int:
        if binding is None:
            return -1
        key = binding.stream.key
        stream = self._stream_index.get(key)
        if stream is None:
            stream = self._stream_index[key] = len(self.keys)
            self.keys.append(key)
        triple = (stream, binding.lo, binding.hi)
        index = self._entry_index.get(triple)
        if index is None:
            index = self._entry_index[triple] = len(self.entries)
            self.entries.append(triple)
        return index

    def event(self, pos: int, msg_id: int) -> None:
        if msg_id >= 0:
            self.events.append((msg_id, pos, self._binding(self.walk.binding(msg_id))))

    def resolve(self, starts: NDArray, msg_ids: NDArray) -> NDArray:
        """The binding of each data record (-1: none) from its msg_id and position."""
        import numpy as np

        ids = msg_ids.astype(np.int64)
        size = max(
            [int(ids.max()) + 1 if len(ids) else 0, *(m + 1 for m in self.initial), *(e[0] + 1 for e in self.events)]
        )
        table = np.full(size, -1, np.int64)  # by msg_id (a log's ids are small numbers)
        for msg_id, b in self.initial.items():
            table[msg_id] = b
        if not self.events:
            return table[ids]
        events = np.array(sorted(self.events), np.int64).reshape(-1, 3)
        # one change per msg_id (the usual): by table (a set of a few ids: np.unique's first call imports numpy.ma)
        if len(set(events[:, 0].tolist())) == len(events):
            since = np.full(size, np.iinfo(np.int64).max, np.int64)
            after = table.copy()
            since[events[:, 0]], after[events[:, 0]] = events[:, 1], events[:, 2]
            return np.where(starts > since[ids], after[ids], table[ids])
        binding = table[ids]
        keys = (events[:, 0] << 40) | events[:, 1]
        at = np.searchsorted(keys, (ids << 40) | starts, side="right") - 1
        later = at >= 0
        later[later] = events[at[later], 0] == ids[later]
        binding[later] = events[at[later], 2]
        return binding

    def tables(self) -> tuple[NDArray, NDArray, NDArray]:
        """(lo, hi, stream) per binding, with a last row for 'none' (index -1) that fits no size."""
        import numpy as np

        rows: Sequence[tuple[int, int, int]] = [*self.entries, (0, 1 << 20, -1)]
        lo = np.array([r[1] for r in rows], np.int64)
        hi = np.array([r[2] for r in rows], np.int64)
        stream = np.array([r[0] for r in rows], np.int64)
        return lo, hi, stream
