"""The compiled ULog walk and gather (codegen/inputs/ulog/_scan.c) called with hostile arguments.

Run as a child process by tests/inputs/test_ulog_scan_bounds.py, so that a crash (a segfault) is
a failed test instead of a dead test run. Every call's outcome is compared with a model of the
bounds written here in Python's unbounded integers: a call the model allows must succeed and copy
exactly the bytes the model names; any other must raise (ValueError, TypeError, OverflowError,
BufferError). Before each call the case is printed, so a crash names the case that caused it.
Prints ``ok <calls>`` at the end; exits 1 on the first disagreement.
"""

from __future__ import annotations

import itertools
import sys
from typing import Any

import numpy as np

from codegen.inputs.ulog._scan import gather, scan

REFUSED = (ValueError, TypeError, OverflowError, BufferError)
BIG = [2**31 - 1, 2**31, 2**32, 2**62, 2**63 - 1]
NEG = [-1, -(2**31), -(2**63)]
OUT_OF_RANGE = [2**63, 2**64, -(2**63) - 1]  # not a Py_ssize_t / int64 at all
calls = 0


def show(*case: Any) -> None:
    print(*case, flush=True)


def fail(message: str) -> None:
    print("MISMATCH", message, flush=True)
    sys.exit(1)


def expect_refused(call: Any, *case: Any) -> None:
    global calls
    calls += 1
    show("refuse?", *case)
    try:
        call()
    except REFUSED:
        return
    fail(f"accepted: {case}")


def gather_cases() -> None:
    global calls
    data = bytes(range(256)) * 4  # 1024 bytes, every byte's value its position mod 256
    n = len(data)
    record_offsets = [0, 1, n - 8, n - 7, n - 1, n, n + 1, *BIG, *NEG]
    record_sizes = [0, 1, 8, n - 1, n, n + 1, *BIG, -1, -(2**63)]
    field_offsets = [0, 3, 7, 8, *BIG, *NEG]
    field_sizes = [0, 1, 4, 8, 9, *BIG, *NEG]
    for o, width, fo, fs in itertools.product(record_offsets, record_sizes, field_offsets, field_sizes):
        out = bytearray(16)
        offsets = np.array([0, o], np.int64)  # the first record is fine: the second decides
        case = ("gather", o, width, fo, fs)
        show(*case)
        calls += 1
        allowed = (
            width >= 0
            and 0 <= fo
            and 0 <= fs
            and fo + fs <= width
            and len(out) // max(fs, 1) >= 2
            and 0 <= o
            and o + width <= n
            and width <= n  # the first record, at 0
        )
        try:
            gather(data, offsets, width, [(fo, fs, out)])
        except REFUSED:
            if allowed:
                fail(f"refused: {case}")
            continue
        if not allowed:
            fail(f"accepted: {case}")
        expected = data[fo : fo + fs] + data[o + fo : o + fo + fs]
        if bytes(out[: 2 * fs]) != expected:
            fail(f"wrong bytes: {case}")
    for value in OUT_OF_RANGE:  # as a record size, a field's offset or size: not even parsed
        expect_refused(lambda v=value: gather(data, np.zeros(1, np.int64), v, []), "gather size", value)
        expect_refused(lambda v=value: gather(data, np.zeros(1, np.int64), 8, [(v, 1, bytearray(8))]), "field", value)
        expect_refused(lambda v=value: gather(data, np.zeros(1, np.int64), 8, [(0, v, bytearray(8))]), "size", value)


def gather_shapes() -> None:
    """Arguments of the wrong kind or shape: refused, never read as something else."""
    global calls
    data, out = bytes(64), bytearray(64)
    wrong_offsets = [
        np.zeros(4, np.int32),  # 4-byte items would be read two at a time
        np.zeros(4, np.uint64),
        np.zeros(4, np.float64),
        np.zeros(4, ">i8" if sys.byteorder == "little" else "<i8"),
        np.arange(8, dtype=np.int64)[::2],  # not contiguous
        b"\0" * 8,
        bytearray(12),
        "offsets",
        None,
    ]
    for offsets in wrong_offsets:
        expect_refused(lambda f=offsets: gather(data, f, 8, [(0, 1, out)]), "offsets", repr(offsets)[:40])
    for spec in [None, 5, [(0, 1)], [(0, 1, b"read-only")], [[0, 1, out]], [(0, 1, out)] * 513, ["abc"]]:
        expect_refused(lambda s=spec: gather(data, np.zeros(1, np.int64), 8, s), "fields", repr(spec)[:40])
    expect_refused(lambda: gather("text", np.zeros(1, np.int64), 8, []), "buffer", "str")
    expect_refused(lambda: gather(data, np.zeros(1, np.int64), 8, [(0, 2, bytearray(1))]), "output", "too small")

    # An unaligned offsets array and unaligned outputs: read and written byte-wise, the same bytes.
    raw = bytearray(8 * 3 + 1)
    unaligned = np.frombuffer(raw, np.int64, count=3, offset=1)
    unaligned[:] = [0, 9, 56]
    target = memoryview(bytearray(25))[1:]
    show("unaligned")
    calls += 1
    gather(bytes(range(64)), unaligned, 8, [(0, 8, target)])
    if bytes(target) != bytes(range(8)) + bytes(range(9, 17)) + bytes(range(56, 64)):
        fail("unaligned offsets or output: wrong bytes")

    # Parsing a field runs Python code (an __index__): it cannot pull the fields from under the loop.
    spec: list[Any] = []

    class Shrinking:
        def __index__(self) -> int:
            spec.clear()
            return 0

    spec.extend([(Shrinking(), 1, bytearray(8)), (0, 1, bytearray(8))])
    show("shrinking spec")
    calls += 1
    gather(data, np.zeros(1, np.int64), 8, spec)


def scan_cases() -> None:
    global calls
    known = bytes(256)
    good = bytes([1, 0, 0x44, 7]) * 64  # records of size 1 and unknown type 'D' (size 1 is allowed)
    n = len(good)
    positions = [0, 1, 4, n - 5, n - 4, n - 1, n, n + 1, *BIG, *NEG]
    for start, stop in itertools.product(positions, positions):
        for out in (bytearray(16 * 8), memoryview(bytearray(16 * 8 + 1))[1:], bytearray(0), bytearray(15)):
            case = ("scan", start, stop, len(out))
            show(*case)
            calls += 1
            allowed = 0 <= start <= stop <= n
            try:
                count, end = scan(good, start, stop, known, out)
            except REFUSED:
                if allowed:
                    fail(f"refused: {case}")
                continue
            if not allowed:
                fail(f"accepted: {case}")
            heads = np.frombuffer(bytes(out[: count * 16]), np.dtype([("pos", "i8"), ("size", "u2"), ("rest", "V6")]))
            if count > len(out) // 16 or not start <= end <= stop:
                fail(f"out of range: {case} -> {count}, {end}")
            if len(heads) and not ((heads["pos"] >= start) & (heads["pos"] + 3 + heads["size"] <= stop)).all():
                fail(f"a record outside [start, stop): {case}")
    for value in OUT_OF_RANGE:
        expect_refused(lambda v=value: scan(good, v, n, known, bytearray(16)), "scan start", value)
        expect_refused(lambda v=value: scan(good, 0, v, known, bytearray(16)), "scan stop", value)
    expect_refused(lambda: scan(good, 0, n, bytes(255), bytearray(16)), "known", 255)
    expect_refused(lambda: scan(good, 0, n, known, bytes(16)), "out", "read-only")
    # A record whose size runs to the very end (65535 bytes claimed in a short buffer): the walk stops there.
    show("scan huge size")
    calls += 1
    count, end = scan(bytes([0xFF, 0xFF, 0x44, 0, 0, 0, 0, 0]), 0, 8, bytes([1]) * 256, bytearray(64))
    if (count, end) != (0, 0):
        fail(f"a record past the end was walked: {count}, {end}")


if __name__ == "__main__":
    gather_cases()
    gather_shapes()
    scan_cases()
    print("ok", calls, flush=True)
