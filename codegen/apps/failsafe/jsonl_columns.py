"""A JSON Lines stream of SI battery samples read as columns, for the columnar replay (:mod:`.columnar`).

A stream written by a program repeats one line shape: the same keys in the same order, only the numbers and
``armed`` changing. Such a stream is read without a JSON parser per line: the first line's text is the template
(its literal text between values), every literal of it is replaced by a one-byte marker over the whole file
(``bytes.replace`` runs in C), the markers must then come in the template's order on every line with one JSON
number (or ``null``) between them, checked over numpy arrays, and the numbers are parsed in one call
(``np.fromstring``, correctly rounded as ``float()`` is). Replacing every marker by its literal gives the file back,
so a file that passes is the template filled with numbers: exactly what ``json.loads`` would have read.

Where the C walk is built (``_jsonl_scan.c``, at install when a compiler is there) the file is mapped, not read,
and walked once: the same literals must be there byte for byte on every line and a JSON number between them, read
as ``float()`` reads it (the numpy reading below is what runs without it, and what the C one is tested against).

Only the plain shape is taken: ``t``, ``armed``, optionally ``instance``, and ``battery`` holding ``voltage_v``,
``current_a`` and/or ``consumed_mah``. Anything else (messages, the distance fields, blank or comment lines, a
line of another shape, a value the per-sample reader would refuse) gives None: the caller reads the stream
sample by sample, with its errors, as before.
"""

from __future__ import annotations

import json
import math
import mmap
import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # the columns module brings the IR along: only its type is needed here
    from ..battery.columns import NDArray

_scan: Callable[[Any, tuple[bytes, ...], bytes, Any, Any, Any], int] | None
try:
    from ._jsonl_scan import scan as _scan
except ImportError:  # no compiler at install: the numpy reading
    _scan = None

TOP = ("t", "armed", "instance", "battery")
BATTERY = ("voltage_v", "current_a", "consumed_mah")
_CONTROL = bytes(b for b in range(32) if b != 10)  # none may be in the file: the markers are its only ones
MAX_BYTES = 1 << 30  # a stream read whole (its columns take about as much again)
NULL = 30  # the byte "null" becomes; markers are 1..29 except the newline
_MARKERS = [b for b in range(1, NULL) if b != 10]
_TOKEN = re.compile(rb'\s+|"(?:[^"\\]|\\.)*"|[{}\[\]:,]|true|false|null|-?[0-9][0-9.eE+-]*')


@dataclass
class SampleColumns:
    """The samples of a stream in file order: line ``k + 1`` is sample ``k``; NaN where a value is null or absent."""

    t: NDArray
    instance: NDArray  # 1-based
    voltage: NDArray
    current: NDArray
    consumed: NDArray
    armed: NDArray  # bool
    data: bytes | mmap.mmap  # the file's bytes, or its memory map (which a file removed meanwhile keeps)
    _ends: NDArray | None = None
    starts: NDArray | None = None  # each line's first byte, then the last one's end + 1 (the C walk finds them)

    def line(self, k: int) -> bytes:
        """The text of sample ``k``'s line."""
        if self.starts is not None:
            return self.data[int(self.starts[k]) : int(self.starts[k + 1]) - 1]
        if self._ends is None:
            self._ends = np.flatnonzero(np.frombuffer(self.data, np.uint8) == 10)
        ends = self._ends
        start = 0 if k == 0 else int(ends[k - 1]) + 1
        return self.data[start : int(ends[k])]


def _template(line: bytes) -> tuple[list[str], list[tuple[int, int]]] | None:
    """The first line's values in text order (their names) and spans, if it has the plain shape."""
    try:
        obj = json.loads(line)
    except (ValueError, RecursionError):  # not JSON, or nested past the parser's depth: the per-sample reader says so
        return None
    if not isinstance(obj, dict) or not {"t", "armed", "battery"} <= obj.keys() or not obj.keys() <= set(TOP):
        return None
    battery = obj["battery"]
    if not isinstance(battery, dict) or not battery.keys() <= set(BATTERY):
        return None
    t, armed, instance = obj["t"], obj["armed"], obj.get("instance", 1)
    if isinstance(t, bool) or not isinstance(t, int | float) or not isinstance(armed, bool):
        return None
    if isinstance(instance, bool) or not isinstance(instance, int):
        return None
    if any(isinstance(v, bool) or not isinstance(v, int | float | None) for v in battery.values()):
        return None
    names: list[str] = []
    for key in obj:
        if key == "battery":
            names.extend(f"battery.{k}" for k in battery)
        else:
            names.append(key)
    spans = [(m.start(), m.end()) for m in _TOKEN.finditer(line) if m.group()[:1] not in b' \t"{}[]:,']
    covered = sum(m.end() - m.start() for m in _TOKEN.finditer(line))
    if covered != len(line) or len(spans) != len(names):
        return None  # a character the tokens do not cover, or a key given twice
    return names, spans


_SLOTS = {"t": 0, "instance": 1, "battery.voltage_v": 2, "battery.current_a": 3, "battery.consumed_mah": 4, "armed": 5}


def read_sample_columns(path: Path, compiled: bool = True, mapped: bool = False) -> SampleColumns | None:
    """The stream's samples as columns, or None where it is not one plain shape throughout (``compiled``: through
    the C walk where it is built; ``mapped``: over a memory map of the file rather than its bytes read, for a caller
    that holds it still while the columns are used, :func:`codegen.inputs.files.held.held`: a map of a file that
    another program truncates meanwhile kills the process with SIGBUS)."""
    try:
        if path.stat().st_size > MAX_BYTES:
            return None  # read line by line instead: memory stays flat
        if _scan is not None and compiled:
            return _read_compiled(path, mapped)
        data = path.read_bytes()
    except OSError:
        return None
    if not data:
        return None
    if not data.endswith(b"\n"):
        data += b"\n"
    first = data[: data.index(b"\n")]
    found = _template(first)
    if found is None:
        return None
    names, spans = found
    # no control byte but the newlines, so that the markers are the file's only ones
    lines = data.count(b"\n")
    if len(data.translate(None, _CONTROL)) != len(data):
        return None
    # the literals between the values; armed's value joins the literals on its sides (one marker for true, one for
    # false)
    cuts = [0, *[x for s in spans for x in s], len(first)]
    literals = [first[cuts[2 * j] : cuts[2 * j + 1]] for j in range(len(spans) + 1)]
    literals[-1] += b"\n"
    groups: list[list[bytes]] = []
    values: list[str] = []
    pending: list[bytes] | None = None
    for j, name in enumerate(names):
        head = [literals[j]] if pending is None else [p + literals[j] for p in pending]
        if name == "armed":
            pending = [h + word for h in head for word in (b"true", b"false")]
            continue
        groups.append(head)
        values.append(name)
        pending = None
    tail = literals[len(names)]
    groups.append([tail] if pending is None else [p + tail for p in pending])
    armed_group = next(i for i, g in enumerate(groups) if len(g) == 2)
    markers: list[list[int]] = []
    out = data
    todo: list[tuple[bytes, int]] = []
    at = 0
    for g in groups:
        markers.append(_MARKERS[at : at + len(g)])
        todo.extend(zip(g, _MARKERS[at : at + len(g)], strict=True))
        at += len(g)
    if len({lit for lit, _ in todo}) != len(todo) or any(b"null" in lit for lit, _ in todo):
        return None
    for lit, mark in sorted(todo, key=lambda x: -len(x[0])):
        out = out.replace(lit, bytes([mark]))
    if b"null" in out:
        out = out.replace(b"null", bytes([NULL]))
    c = np.frombuffer(out, np.uint8)
    is_mark = c < NULL
    pos = np.flatnonzero(is_mark)
    per_line = len(groups)
    if len(pos) != lines * per_line or not len(pos) or pos[0] != 0 or pos[-1] != len(c) - 1:
        return None
    seq = c[pos].reshape(lines, per_line)
    for i, mk in enumerate(markers):
        if len(mk) == 1:
            if not (seq[:, i] == mk[0]).all():
                return None
        elif not np.isin(seq[:, i], mk).all():
            return None
    armed = seq[:, armed_group] == markers[armed_group][0]
    # every value a token (a marker is followed by a number), nothing between a line's end and the next's start
    followed = np.append(is_mark[pos[:-1] + 1], True).reshape(lines, per_line)
    if followed[:, :-1].any() or not followed[:, -1].all():
        return None
    if not _numbers_valid(c, pos, per_line, [values.index("instance")] if "instance" in values else []):
        return None
    grid = pos.reshape(lines, per_line)
    numbers = _parse(out, c, (grid[:, :-1] + 1).ravel(), grid[:, 1:].ravel())
    if numbers is None:
        return None
    table = numbers.reshape(lines, len(values))

    def column(name: str, default: float = np.nan) -> NDArray:
        return table[:, values.index(name)] if name in values else np.full(lines, default)

    t = column("t")
    instance = column("instance", 1.0)
    voltage, current, consumed = (column(f"battery.{k}") for k in BATTERY)
    if not np.isfinite(t).all() or not np.isfinite(instance).all():
        return None  # the per-sample reader's error
    if ((instance < 1) | (instance > 16)).any():
        return None
    for col in (voltage, current, consumed):
        if np.isinf(col).any():
            return None  # a number beyond a float: the per-sample reader's business
    return SampleColumns(t, instance.astype(np.int64), voltage, current, consumed, armed, data)


def _read_compiled(path: Path, mapped: bool) -> SampleColumns | None:
    """The C walk over the file, mapped or read (OSError where it cannot be)."""
    assert _scan is not None
    data: bytes | mmap.mmap
    with path.open("rb") as f:
        if not os.fstat(f.fileno()).st_size:
            return None
        # the events' lines are read from it later
        data = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) if mapped else f.read()
    end = data.find(b"\n")
    first = data[: end if end >= 0 else len(data)]
    found = _template(first)
    if found is None or len(first.translate(None, _CONTROL)) != len(first):
        return None  # no control byte in the literals (a tab, a carriage return): the numpy reading's rule
    names, spans = found
    cuts = [0, *[x for s in spans for x in s], len(first)]
    literals = tuple(first[cuts[2 * j] : cuts[2 * j + 1]] for j in range(len(spans) + 1))
    slots = bytes(_SLOTS[name] for name in names)
    shortest = sum(map(len, literals)) + len(slots)  # a line's fewest bytes: one a value
    capacity = len(data) // shortest + 1
    columns = np.empty((5, capacity))
    armed = np.empty(capacity, np.uint8)
    starts = np.empty(capacity + 1, np.int64)
    lines = _scan(data, literals, slots, columns, armed, starts)
    if lines <= 0:
        return None
    # min and max tell NaN (they propagate it) and inf without a temporary column; fmin / fmax skip the nulls
    table = columns[:, :lines]
    t = table[0]
    if not (math.isfinite(t.min()) and math.isfinite(t.max())):
        return None  # the per-sample reader's error
    instance = np.ones(lines, np.int64)
    if "instance" in names:
        if not (1 <= table[1].min() and table[1].max() <= 16):  # NaN fails both
            return None  # the per-sample reader's error
        instance = table[1].astype(np.int64)
    voltage, current, consumed = (
        table[2 + i] if f"battery.{k}" in names else np.full(lines, np.nan) for i, k in enumerate(BATTERY)
    )
    for col in (voltage, current, consumed):
        if np.fmax.reduce(col) == np.inf or np.fmin.reduce(col) == -np.inf:
            return None  # a number beyond a float: the per-sample reader's business
    flags = armed[:lines].view(np.bool_)  # the walk writes 0 or 1
    return SampleColumns(t, instance, voltage, current, consumed, flags, data, starts=starts[: lines + 1])


_U64 = np.uint64
_LOW = np.array([(1 << (8 * n)) - 1 for n in range(9)], _U64)  # the low n bytes of a word
_ZEROS = _U64(0x3030303030303030)  # eight "0"
_POW10 = 10.0 ** np.arange(9)


def _parse(out: bytes, c: NDArray, start: NDArray, end: NDArray) -> NDArray | None:
    """The tokens ``out[start:end]`` (valid JSON numbers or the null byte) as floats, as ``json.loads`` reads them
    (then ``float()``). A token of at most eight digits with a point or none, the most a log writes, is read eight
    bytes at a time: its digits as one integer (the SWAR reading of eight ASCII digits), divided by a power of ten,
    both exact, so the quotient is the correctly rounded value ``float()`` gives. Other tokens are read one by one."""
    padded = out + bytes(16)
    words = np.ndarray(shape=(len(padded) - 7,), dtype="<u8", buffer=padded, strides=(1,))
    neg = c[start] == ord("-")
    first = start + neg
    size = end - first
    w = words[first] & _LOW[np.minimum(size, 8)]
    dots = _zero_bytes(w ^ _U64(0x2E2E2E2E2E2E2E2E))
    odd = _zero_bytes(w ^ _U64(0x6565656565656565)) | _zero_bytes(w ^ _U64(0x4545454545454545))
    odd |= _zero_bytes(w ^ _U64(0x1E1E1E1E1E1E1E1E))  # an exponent or a null: read one by one
    has_dot = dots != 0
    lowest = np.where(has_dot, dots & (~dots + _U64(1)), _U64(1) << _U64(63))
    d = (np.log2(lowest.astype(np.float64)).astype(np.int64) - 7) // 8  # the point's byte; 7 without one
    digits = size - has_dot
    fast = (odd == 0) & (digits >= 1) & (digits <= 8)
    n = np.clip(digits, 0, 8)
    low = _LOW[d]
    w = np.where(has_dot, (w & low) | ((w >> _U64(8)) & ~low), w)
    nine = np.flatnonzero(has_dot & (size == 9))  # the ninth byte, past the word, is the last digit
    if len(nine):
        w[nine] |= c[first[nine] + 8].astype(_U64) << _U64(56)
    w &= _LOW[n]
    w = (w << (_U64(8) * (_U64(8) - n.astype(_U64)))) | (_ZEROS & _LOW[8 - n])
    w = ((w & _U64(0x0F0F0F0F0F0F0F0F)) * _U64(2561)) >> _U64(8)
    w = ((w & _U64(0x00FF00FF00FF00FF)) * _U64(6553601)) >> _U64(16)
    w = ((w & _U64(0x0000FFFF0000FFFF)) * _U64(42949672960001)) >> _U64(32)
    value = w.astype(np.float64) / _POW10[np.where(has_dot, np.clip(size - 1 - d, 0, 8), 0)]
    # a minus makes a negative, but "-0" is the integer 0 (+0.0), as json reads it; "-0.0" is -0.0
    numbers = np.where(neg & (has_dot | (w != 0)), -value, value)
    for i in np.flatnonzero(~fast).tolist():
        token = out[start[i] : end[i]]
        if token == bytes([NULL]):
            numbers[i] = np.nan
        elif b"." in token or b"e" in token or b"E" in token:
            numbers[i] = float(token)
        else:
            try:
                numbers[i] = float(int(token))
            except OverflowError:
                return None  # an integer beyond a float: the per-sample reader's business
    return numbers


def _zero_bytes(x: NDArray) -> NDArray:
    """The high bit of each byte of ``x`` that is zero (exact for the lowest such byte; 0 when none is)."""
    return (x - _U64(0x0101010101010101)) & ~x & _U64(0x8080808080808080)


def _numbers_valid(c: NDArray, pos: NDArray, per_line: int, integers: list[int]) -> bool:
    """Every token between two markers is a JSON number (or null); those after the groups ``integers`` are digits
    only. Checked at the few characters that are not digits (signs, points, exponents, nulls) and at the tokens'
    ends, not over every byte again."""
    kind = _KIND[c]
    if (kind == _BAD).any():
        return False
    special = np.flatnonzero(kind >= _MINUS)
    at = kind[special]
    prev, nxt = kind[special - 1], kind[special + 1]  # a line starts and ends with a marker: both exist
    bad = (at == _MINUS) & (prev != _MARK) & (prev != _EXP)
    bad |= (at == _PLUS) & (prev != _EXP)
    bad |= ((at == _DOT) | (at == _EXP)) & (prev != _DIGIT_KIND)
    bad |= (at == _NULL_KIND) & ((prev != _MARK) | (nxt != _MARK))
    bad |= (at != _NULL_KIND) & (nxt == _MARK)  # a token ends with a digit (or is null)
    if bad.any():
        return False
    # a leading zero followed by a digit ("01", "-01"; an exponent's zeros are fine)
    zeros = np.flatnonzero(c[pos[:-1] + 1] == ord("0"))
    zeros = pos[:-1][zeros] + 1
    minus = pos[:-1][c[pos[:-1] + 1] == ord("-")] + 2
    for first in (zeros, minus[c[minus] == ord("0")]):
        if (kind[first + 1] == _DIGIT_KIND).any():
            return False
    # at most one point and one exponent a token, the point before the exponent; integers without either
    token = np.searchsorted(pos, special) - 1
    dots, exps = token[at == _DOT], token[at == _EXP]
    if (np.diff(dots) == 0).any() or (np.diff(exps) == 0).any():  # in order: a repeat is a neighbour
        return False
    if len(dots) and len(exps):
        exp_at = np.full(len(pos), -1, np.int64)
        exp_at[exps] = special[at == _EXP]
        dot_at = special[at == _DOT]
        if ((exp_at[dots] >= 0) & (exp_at[dots] < dot_at)).any():
            return False
    return not any((token % per_line == g).any() for g in integers)


_MARK, _DIGIT_KIND, _BAD, _MINUS, _PLUS, _DOT, _EXP, _NULL_KIND = range(8)
_KIND = np.full(256, _BAD, np.uint8)
_KIND[_MARKERS] = _MARK
_KIND[ord("0") : ord("9") + 1] = _DIGIT_KIND
_KIND[ord("-")], _KIND[ord("+")], _KIND[ord(".")] = _MINUS, _PLUS, _DOT
_KIND[ord("e")] = _KIND[ord("E")] = _EXP
_KIND[NULL] = _NULL_KIND
