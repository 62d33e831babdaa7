"""The C walk of a plain JSON Lines stream (codegen/apps/failsafe/_jsonl_scan.c) reads what ``json.loads`` reads and
the numpy reading reads: every number bit for bit (the fast path and Python's parser for the rest), the same lines
refused, each line found again; hostile arguments are refused, never crashed on (in a child process)."""

from __future__ import annotations

import json
import os
import random
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from test_failsafe_jsonl_columns import GOOD

from codegen.apps.failsafe import jsonl_columns
from codegen.apps.failsafe.jsonl_columns import SampleColumns, read_sample_columns

# tokens at the edges of the fast path (19 digits, 2**53, 22 places) and past them, signed zeros, exponents,
# subnormals, halfway cases a naive division would round wrongly
EDGES = [
    "0", "-0", "0.0", "-0.0", "7", "-7", "0.05", "11.999", "16.926", "0.1", "0.30000000000000004", "1e5", "1E+2",
    "-1.5e-3", "2e0", "0e0", "-0e-0", "123456789012345678", "1234567890123456789", "12345678901234567890",
    "12345678901234567890123", "9007199254740992", "9007199254740993", "9007199254740992.5", "900719925474099.3",
    "0.1234567890123456789", "0.12345678901234567890123", "1.2345678901234567890123", "0.0000000000000000000001",
    "0.00000000000000000000001", "1.7976931348623157e308", "5e-324", "2.2250738585072011e-308",
    "4.9406564584124654e-324", "2.5e-324", "1e22", "1e23", "10000000000000000000000", "9.999999999999999e22",
    "0.5", "1.5", "2.675", "1" * 70, "0." + "3" * 400 + "e-5", "-" + "9" * 308,
    "1.0000000000000002", "0.9999999999999999", "3.141592653589793238462643383279",
]  # fmt: skip


def _tokens() -> list[str]:
    """The edges and a fixed draw of others: repr of doubles, decimal strings of 1..25 digits at any point."""
    rng = random.Random(30)
    out = list(EDGES)
    for _ in range(3000):
        bits = rng.getrandbits(64)
        x = struct.unpack("<d", struct.pack("<Q", bits))[0]
        if x == x and abs(x) != float("inf"):
            out.append(repr(x))
    for _ in range(3000):
        digits = "".join(rng.choice("0123456789") for _ in range(rng.randint(1, 25))).lstrip("0") or "0"
        point = rng.randint(0, len(digits))
        text = digits if point in (0, len(digits)) else f"{digits[:point]}.{digits[point:]}"
        if rng.random() < 0.3:
            text += f"e{rng.randint(-30, 30)}"
        out.append(("-" if rng.random() < 0.5 else "") + text)
    return out


def _compiled() -> None:
    if jsonl_columns._scan is None:
        if os.environ.get("CI") == "true":
            pytest.fail("the C extension codegen/apps/failsafe/_jsonl_scan.c was not built (CI has gcc)")
        pytest.skip("the C extension is not built")


def _both(text: str) -> tuple[SampleColumns | None, SampleColumns | None]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.jsonl"
        path.write_text(text, encoding="utf-8")
        return read_sample_columns(path), read_sample_columns(path, compiled=False)


def _bits(column: np.ndarray) -> list[int]:
    return np.ascontiguousarray(column, np.float64).view(np.uint64).tolist()


def test_every_number_is_read_as_json_reads_it() -> None:
    _compiled()
    tokens = _tokens()
    lines = [f'{{"t": {k}, "armed": {"true" if k % 2 else "false"}, "battery": {{"voltage_v": {tok}, '
             f'"current_a": {tok}, "consumed_mah": null}}}}' for k, tok in enumerate(tokens)]  # fmt: skip
    compiled, numpy = _both("\n".join(lines))  # no final newline
    assert compiled is not None and numpy is not None
    expected = [float(json.loads(line)["battery"]["voltage_v"]) for line in lines]
    assert _bits(compiled.voltage) == _bits(np.array(expected)) == _bits(numpy.voltage)
    assert _bits(compiled.current) == _bits(compiled.voltage) and np.isnan(compiled.consumed).all()
    assert compiled.t.tolist() == list(range(len(tokens))) and compiled.armed.tolist() == numpy.armed.tolist()
    for k in (0, 1, len(lines) // 2, len(lines) - 1):
        assert compiled.line(k) == numpy.line(k) == lines[k].encode()


@pytest.mark.parametrize(
    "tail",
    [
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 01, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": -, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1.e3, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1e+, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": nul, "current_a": 3}}',
        '{"t": 2.0, "armed": tru, "battery": {"voltage_v": 1, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1, "current_a": 3}}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1, "current_a": 3}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1e999, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1\t, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1, "current_a": 3}}\r',
        "",
    ],
)
def test_both_readings_refuse_the_same_lines(tail: str) -> None:
    _compiled()
    compiled, numpy = _both(GOOD + tail + "\n" + GOOD)
    assert compiled is None and numpy is None


def test_both_readings_take_a_final_line_without_its_newline() -> None:
    _compiled()
    for text in (GOOD, GOOD + GOOD.rstrip("\n"), GOOD * 3):
        compiled, numpy = _both(text)
        assert compiled is not None and numpy is not None
        n = len(compiled.t)
        with tempfile.TemporaryDirectory() as tmp:  # the memory map a replay holding the file reads through
            path = Path(tmp) / "s.jsonl"
            path.write_text(text, encoding="utf-8")
            mapped = read_sample_columns(path, mapped=True)
            assert mapped is not None and not isinstance(mapped.data, bytes)
            assert [mapped.line(k) for k in range(n)] == [compiled.line(k) for k in range(n)]
            assert mapped.voltage.tolist() == compiled.voltage.tolist()
            mapped.data.close()
        assert n == text.count('{"t"') and [compiled.line(k) for k in range(n)] == [numpy.line(k) for k in range(n)]


HOSTILE = """
import numpy as np
from codegen.apps.failsafe._jsonl_scan import scan
line = b'{"t": 1, "armed": true, "battery": {"voltage_v": 2}}'
lits, slots = (b'{"t": ', b', "armed": ', b', "battery": {"voltage_v": ', b'}}'), bytes([0, 5, 2])
def cols(n):
    return np.empty((5, n)), np.empty(n, np.uint8), np.empty(n + 1, np.int64)
refused = 0
for args in [
    (line, lits, bytes([0, 5, 9]), *cols(4)),  # a slot code past 5
    (line, lits[:-1], slots, *cols(4)),  # a literal short
    (line, (b"a", 1, b"b", b"c"), slots, *cols(4)),  # not bytes
    (line, (), b"", *cols(4)),  # no slot
    (line, lits * 9, slots * 9, *cols(4)),  # too many slots
    (line, lits, slots, np.empty((5, 4)), np.empty(2, np.uint8), np.empty(5, np.int64)),  # armed too small
    (line, lits, slots, np.empty((5, 4)), np.empty(4, np.uint8), np.empty(4, np.int64)),  # starts too small
    (line, lits, slots, b"read-only" * 40, *cols(4)[1:]),  # not writable
    (line, list(lits), slots, *cols(4)),  # not a tuple
]:
    try:
        scan(*args)
    except (ValueError, TypeError):
        refused += 1
assert scan(line * 3, lits, slots, *cols(0)) == -1  # no room: the walk stops
assert scan(b"", lits, slots, *cols(0)) == 0
c = cols(2)
assert scan(line + b"\\n" + line[:-3], lits, slots, *c) == -1  # a line cut short
print("refused", refused)
"""


def test_hostile_arguments_are_refused_not_crashed_on() -> None:
    _compiled()
    run = subprocess.run([sys.executable, "-c", HOSTILE], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["refused", "9"]
