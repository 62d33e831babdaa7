"""``battgen convert`` on real PX4 logs and on what used to stop it: the strict policy never refuses
a real record (a value the target cannot hold is its "unknown" plus a loss entry naming file,
record and field; exit 1), every battery instance is converted, inputs without records and bad
output paths are one clear line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from pyulog import ULog
from shared_data import REAL_LOGS, missing

from codegen.cli.main import main
from generated.convert import LossReport
from generated.convert._cells import mavlink_cells_out


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def real(name: str) -> Path:
    path = REAL_LOGS / name
    if not path.is_file():
        missing("the shared real PX4 logs")
    return path


def test_older_log_to_mavlink_carries_its_cells_in_millivolts(capsys: pytest.CaptureFixture[str]) -> None:
    path = real("sample_log_small.ulg")
    code, out, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", "--report", str(path))
    records = [json.loads(line) for line in out.splitlines()]
    theirs = {d.multi_id: d.data for d in ULog(str(path), ["battery_status"]).data_list}
    assert len(records) == sum(len(d["timestamp"]) for d in theirs.values()) == 42  # both batteries
    seen = {0: 0, 1: 0}
    for rec in records:
        source = rec["source"]
        multi_id, i = source["multi_id"], seen[source["multi_id"]]
        seen[multi_id] += 1
        cols = theirs[multi_id]
        assert source["timestamp_us"] == int(cols["timestamp"][i]) and source["file"] == str(path)
        cells = [float(cols[f"voltage_cell_v[{k}]"][i]) for k in range(10)][: int(cols["cell_count"][i])]
        main_cells = rec["record"]["voltages"]
        assert main_cells[: min(10, len(cells))] == [round(c * 1000) for c in cells][:10]
        assert all(v == 65535 for v in main_cells[len(cells) :])
    # battery 2 has 12 cells, the old layout only 10 voltages: cells 11 and 12 are unknown
    assert code == 1
    assert "record 2 (battery_status multi_id 1, timestamp 20630671 us, offset 86464)" in err
    assert "mavlink.BATTERY_STATUS.voltages_ext: cell 11 unknown (NaN), sent as 0 (no cell) (21 records" in err
    assert records[1]["record"]["voltages_ext"] == [0, 0, 0, 0]
    assert {
        "kind": "unrepresentable",
        "field": "mavlink.BATTERY_STATUS.voltages_ext",
        "detail": "cell 12 unknown (NaN), sent as 0 (no cell)",
    } in records[1]["loss"]


@pytest.mark.parametrize("name", ["sample_log_small.ulg", "sample_px4_events.ulg"])
@pytest.mark.parametrize("target", ["mavlink", "dronecan"])
def test_both_real_logs_convert_strictly(name: str, target: str, capsys: pytest.CaptureFixture[str]) -> None:
    path = real(name)
    code, out, err = run(capsys, "convert", "--from", "uorb", "--to", target, str(path))
    lines = out.splitlines()
    assert len(lines) == {"sample_log_small.ulg": 42, "sample_px4_events.ulg": 157}[name]
    expected = 1 if (name, target) == ("sample_log_small.ulg", "mavlink") else 0
    assert code == expected, err
    assert "cannot convert" not in err and "Traceback" not in err
    if (name, target) == ("sample_px4_events.ulg", "mavlink"):
        # a cell count without cell voltages: the pack voltage in cell 1, as MAVLink asks
        first = json.loads(lines[0])
        assert first["voltages"][0] == 16200 and first["voltages"][1:] == [65535] * 9


def test_nan_cells_become_the_marker_with_a_loss_entry() -> None:
    report = LossReport()
    main_cells, ext = mavlink_cells_out([3700.0, math.nan, 3710.0] + [3700.0] * 8 + [math.nan], None, 10, 4,
                                        65535, 0, report, "m.voltages", "m.voltages_ext")  # fmt: skip
    assert main_cells[:3] == [3700, 65535, 3710] and ext == [3700, 0, 0, 0]
    assert [(e.kind, e.field, e.detail) for e in report if e.kind == "unrepresentable"] == [
        ("unrepresentable", "m.voltages", "cell 2 unknown (NaN), sent as 65535 (no cell)"),
        ("unrepresentable", "m.voltages_ext", "cell 12 unknown (NaN), sent as 0 (no cell)"),
    ]
    report = LossReport()
    all_unknown = mavlink_cells_out([math.nan] * 4, 16200.0, 10, 4, 65535, 0, report, "m.v", "m.x")
    assert all_unknown == ([16200] + [65535] * 9, [0] * 4) and not report.fields("unrepresentable")


def test_an_input_without_records_is_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text("\n")
    code, out, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(src))
    assert (code, out) == (1, "") and f"{src}: no records to convert (--allow-empty accepts that)" in err
    code, _, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", "--allow-empty", str(src))
    assert code == 0 and err == ""


def test_output_paths_are_one_clear_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.json"
    src.write_text('{"voltage_v": 12}')
    missing = tmp_path / "no" / "such" / "out.json"
    code, _, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(src), "-o", str(missing))
    assert code == 2 and err.strip() == f"battgen: -o {missing}: the folder {missing.parent} does not exist"
    code, _, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(src), "-o", str(tmp_path))
    assert code == 2 and err.strip() == f"battgen: -o {tmp_path}: is a folder; expected a file name"
