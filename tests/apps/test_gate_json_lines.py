"""``battgen validate`` of JSON Lines judges a line by ``from_dict`` and ``validate()`` and builds a Record only for
a line with findings: what it reports is what checking every line as a Record reports (findings, their lines and
records, unreadable lines, counts), whatever the lines hold."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.apps.gate.selection import Gate, Settings
from codegen.apps.gate.validate import Checker, FileReport, check_file, make_checker

VALID = {"voltage_v": 16.4, "remaining": 0.5, "cell_count": 4, "max_error": 1, "temperature": "NaN"}
LINES = [
    json.dumps(VALID),
    json.dumps({**VALID, "remaining": 1.5}),  # a range
    json.dumps({**VALID, "voltage_cell_v": [4.0] * 5 + [0.0] * 9}),  # a cross-field rule
    json.dumps({**VALID, "voltage_v": "high"}),  # not a number
    json.dumps({**VALID, "wattage": 3}),  # not a field
    json.dumps({**VALID, "timestamp": 18446744073709551616}),  # beyond uint64, beyond what orjson keeps exact
    json.dumps({**VALID, "capacity": 12345678901234567890123}),
    "[1, 2]",  # not an object
    "{not json",
    "",
    "NaN",
    '{"voltage_v": NaN, "max_error": 1}',
    json.dumps({**VALID, "state_of_health": 120, "max_error": 0}),  # two findings on one line
    json.dumps(VALID),
]


def _report(path: Path, checker: Checker, gate: Gate | None) -> FileReport:
    return check_file(path, checker.message, checker, gate=gate)


@pytest.mark.parametrize("ignore", [(), ("range",)])
def test_blocks_report_what_records_report(tmp_path: Path, ignore: tuple[str, ...]) -> None:
    path = tmp_path / "records.jsonl"
    path.write_text("\n".join(LINES * 3) + "\n", encoding="utf-8")
    _, checker = make_checker(ROOT / "schemas", "uorb.BatteryStatus")
    assert checker.plain
    every_record = Checker(checker.cls, checker.message, checker.data_error, checker.rules, None, None)
    every_record.plain = False  # each line through read_records and Checker.check, as other kinds are
    gate = Gate(Settings(ignore=ignore), "uorb.BatteryStatus") if ignore else None
    fast, slow = _report(path, checker, gate), _report(path, every_record, gate)
    assert dataclasses.asdict(fast) == dataclasses.asdict(slow)
    assert fast.records == 12 * 3 and len(fast.unreadable) == 3 and fast.errors > 0  # "{not json" alone unreadable
    assert {f.line for f in fast.findings} >= {2, 3, 4, 5, 6, 7, 8, 13}
