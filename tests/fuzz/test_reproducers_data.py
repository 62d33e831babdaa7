"""The data-side reproducers of issue 10, each held to a clear ending in bounded time and memory.

Every hostile input here once hung, crashed or blew up memory. Each runs through the real command in a
subprocess (tests/fuzz/measure.py) and must end with exit 1 or 2, a message naming the file, no traceback,
a peak RSS far below what the regression cost and a wall time far below the hang.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from measure import assert_bounded, run_battgen

from generated._validate import fmt, span
from generated.uorb import BatteryStatus

# -- a corrupt count drives a rule's loop ------------------------------------------------------------------


@pytest.mark.parametrize("count", [-100_000_000, -780_000_000_000, 10**30])
def test_corrupt_cell_count_is_reported_not_looped_over(count: int) -> None:
    found = BatteryStatus(cell_count=count).validate()
    [bad] = [v for v in found if v.path == "cell_count" and v.rule == "type-bounds"]
    assert "does not fit uint8" in bad.message
    # the loop of cells-beyond-count-zero stays inside voltage_cell_v's 14 cells: no wrapped negative index
    assert all(not v.path.startswith("voltage_cell_v[-") for v in found)


def test_a_rule_range_is_clamped_to_the_schema_capacity() -> None:
    assert span(-(10**8), 14, limit=14) == range(0, 14)
    assert span(3, 10**12, limit=14) == range(3, 14)
    assert span(10**12, limit=14) == range(0, 14)
    assert span(5, limit=14) == range(0, 5)
    # a real violation past the count is still found
    found = BatteryStatus(cell_count=2, voltage_cell_v=[3.7, 3.7, 3.7] + [0.0] * 11).validate()
    assert [v.path for v in found if v.rule == "cross-field:cells-beyond-count-zero"] == ["voltage_cell_v[2]"]


def test_messages_quote_huge_values_briefly() -> None:
    assert fmt(10**5000) == "<an integer of 5001 digits>" and fmt(-(10**200)).startswith("-<an integer")
    bomb: list[object] = ["lol"] * 8
    for _ in range(12):  # what a YAML alias bomb expands to: 8**12 leaves, never walked
        bomb = [bomb] * 8
    assert len(fmt(bomb)) < 200
    assert len(fmt("x" * 10**6)) <= 60 and len(fmt(b"\0" * 10**6)) < 200
    assert len(fmt({"k": [bomb] * 1000})) <= 60


def test_corrupt_count_in_a_file_ends_quickly(tmp_path: Path) -> None:
    path = tmp_path / "corrupt.jsonl"
    path.write_text('{"cell_count": -100000000}\n{"cell_count": -780000000000}\n')
    result = run_battgen("validate", "--message", "uorb.BatteryStatus", str(path))
    assert_bounded(result, codes=(1,), seconds=30)
    assert f"{path.as_posix()}:1: cell_count = -100000000 does not fit uint8" in result.stdout
