"""A battery's number out of its type (a DataFlash ``BAT.Inst`` of 2^32 or beyond int64, a JSON Lines uORB ``id``
of 2^32 + 1): the record is left out and said so, never cast into another battery's number (two packs would
merge into one flight) and never a traceback."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.view import read_view
from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from dataflash_writer import DataflashWriter


def _bin(path: Path, instances: list[int]) -> Path:
    w = DataflashWriter()
    w.define("BAT", "QQfff", ("TimeUS", "Inst", "Volt", "Curr", "CurrTot"))
    for i, inst in enumerate(instances):
        w.write("BAT", 1_000_000 * (i + 1), inst, 12.0, 1.0, float(i))
    return w.save(path)


def test_dataflash_instances_beyond_a_battery_number_are_left_out(tmp_path: Path) -> None:
    log = _bin(tmp_path / "f.bin", [0, 2**32, 0, 2**64 - 1, 1])
    chunks = list(read_view(log, "f.bin", catalog=bundled_catalog()))
    batteries = sorted((int(c.battery[0]), c.n) for c in chunks)
    assert batteries == [(0, 2), (1, 1)]  # 2^32 did not join battery 0
    warnings = [w for c in chunks for w in c.batch.warnings]
    assert warnings == ["f.bin: 2 battery record(s) left out whose instance is no battery's (0..255): 4294967296, "
                        "18446744073709551615"]  # fmt: skip


def test_json_lines_ids_beyond_uint8_are_left_out_with_their_line(tmp_path: Path) -> None:
    rows = [
        {"timestamp": 1_000_000 * (i + 1), "voltage_v": 12.0, "id": v}
        for i, v in enumerate([1, 2**32 + 1, 2**70, -3, 1])
    ]
    log = tmp_path / "f.jsonl"
    log.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    chunks = list(read_view(log, "f.jsonl", catalog=bundled_catalog(), message="uorb.BatteryStatus"))
    assert [list(c.battery) for c in chunks] == [[0, 0]]  # uORB ids are 1-based
    assert chunks[0].batch.warnings == [
        "f.jsonl:2: id = 4294967297 does not fit uint8 (0..255): record left out",
        "f.jsonl:3: id = 1180591620717411303424 does not fit uint8 (0..255): record left out",
        "f.jsonl:4: id = -3 does not fit uint8 (0..255): record left out",
    ]


def test_export_says_what_it_left_out_and_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = _bin(tmp_path / "f.bin", [0, 2**40, 0])
    code = main(["export", str(log), "-o", str(tmp_path / "ds"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert "f.bin: 1 battery record(s) left out whose instance is no battery's (0..255): 1099511627776" in err
