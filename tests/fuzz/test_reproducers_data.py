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


# -- tiny files, unbounded memory --------------------------------------------------------------------------

CRASHERS = Path(__file__).resolve().parent / "crashers"


def test_ulog_array_beyond_the_message_size_is_refused() -> None:
    path = CRASHERS / "cli-ulog" / "array-of-999999999999-bytes.ulg"  # 161 bytes; once 5.7 GB and a MemoryError
    for argv in (["validate", "--message", "uorb.BatteryStatus"], ["convert", "--from", "uorb", "--to", "mavlink"]):
        result = run_battgen(*argv, str(path))
        # the reader recovers from the bad format record (a damaged log): a warning, not a failure
        assert_bounded(result, codes=(0, 1, 2))
        assert "array 'uint8_t[999999999999] x' is longer than a ULog message holds (65535 bytes)" in result.stderr


def test_incbin_reads_no_device_and_nothing_outside_the_board_folder(tmp_path: Path) -> None:
    board = tmp_path / "board.dts"
    board.write_text((CRASHERS / "cli-dts" / "incbin-dev-zero.dts").read_text())
    result = run_battgen("validate", "--message", "simple-battery", str(board))
    assert_bounded(result, codes=(2,))
    assert f'{board.as_posix()}:7: /incbin/ "/dev/zero": outside the folder of' in result.stdout + result.stderr
    (tmp_path / "blob.bin").write_bytes(bytes(range(16)) * 4096)
    board.write_text(board.read_text().replace('"/dev/zero", 0, 4', '"blob.bin", 4, 2'))
    result = run_battgen("validate", "--format", "json", "--message", "simple-battery", str(board))
    assert_bounded(result, codes=(0, 1))  # the slice is read; blob is no property of a simple-battery


def test_yaml_alias_bomb_is_never_expanded() -> None:
    bomb = CRASHERS / "cli-yaml" / "alias-bomb-9x9.yaml"  # 9**9 = 387 million strings once expanded
    for argv in (
        ["validate", "--message", "uorb.BatteryStatus"],
        ["validate", "--format", "json", "--message", "uorb.BatteryStatus"],
        ["convert", "--from", "uorb", "--to", "mavlink"],
    ):
        result = run_battgen(*argv, str(bomb))
        assert_bounded(result, seconds=30)
        said = result.stdout + result.stderr
        assert bomb.as_posix() in said and "cell_count: expected an integer, got [['lol', 'lol', 'lol'" in said


def test_json_lines_line_length_is_bounded(tmp_path: Path) -> None:
    path = tmp_path / "long.jsonl"
    with path.open("w") as out:  # 50 MB on one line: read whole, it cost ten times that
        out.write('{"voltage_v": 12.0, "max_error": 1}\n{"voltage_cell_v": [')
        out.write("1.0, " * 10_000_000)
        out.write('1.0]}\n{"voltage_v": 11.0, "max_error": 1}\n')
    result = run_battgen("validate", "--message", "uorb.BatteryStatus", str(path))
    assert_bounded(result, codes=(2,), rss_mb=150)
    assert f"{path.as_posix()}:2: a line of 50000026 characters, longer than the 1048576" in result.stderr
    assert "2 records in 1 file" in result.stderr


# -- data commands: huge integers, deep nesting ----------------------------------------------------------


def test_huge_integers_and_deep_nesting_are_located_errors(tmp_path: Path) -> None:
    deep = CRASHERS / "cli-json" / "nested-100000-deep.json"
    digits = CRASHERS / "cli-json" / "integer-of-5000-digits.json"
    lines = tmp_path / "digits.jsonl"
    # a first record validate passes (uORB's max_error is 1..100): strict convert refuses what validate refuses
    lines.write_text('{"voltage_v": 12.0, "max_error": 1}\n' + digits.read_text())
    yaml_digits = CRASHERS / "cli-yaml" / "integer-of-5000-digits.yaml"
    for path, where in ((deep, ":1: values nested too deeply"), (digits, ":1: expected a number a battery field"),
                        (lines, ":2: expected a number a battery field"), (yaml_digits, ":1: ")):  # fmt: skip
        result = run_battgen("convert", "--from", "uorb", "--to", "mavlink", str(path))
        assert_bounded(result, codes=(2,))
        assert f"{path.as_posix()}{where}" in result.stderr
    result = run_battgen(
        "validate", "--message", "uorb.BatteryStatus", str(deep), str(digits), str(lines), str(yaml_digits)
    )
    assert_bounded(result, codes=(2,))
    assert "cannot read: ValueError" not in result.stdout + result.stderr
    assert f"{yaml_digits.as_posix()}:1: malformed YAML: an integer of 5000 digits" in result.stderr


def test_parameter_value_of_5000_digits() -> None:
    path = CRASHERS / "cli-params" / "value-of-5000-digits.params"
    for argv in (["params", "--check"], ["validate"]):
        result = run_battgen(*argv, str(path))
        assert_bounded(result, codes=(2,))
        assert (
            f"{path.as_posix()}:1: expected a parameter value (float32 or a 32-bit integer), got a number of 5000"
            in (result.stdout + result.stderr)
        )
