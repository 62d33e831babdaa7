"""A log that grew between runs (a tlog downloaded again with more frames, a JSON Lines file appended to) is one
flight: its new export replaces the earlier one, in one atomic step, with a line saying so; a file of the same
name whose start differs is another flight."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from codegen.apps.export import engine
from codegen.apps.export.engine import ExportOptions, export_logs
from codegen.apps.export.manifest import LOGS, committed
from codegen.apps.export.query import run_query
from codegen.cli.main import main


def _records(first: int, n: int, volts: float = 12.0) -> str:
    rows = [
        {"timestamp": 1_000_000 * (i + 1), "voltage_v": volts - i * 0.01, "current_a": 3.0}
        for i in range(first, first + n)
    ]
    return "".join(json.dumps(r) + "\n" for r in rows)


def _flights(out: Path) -> list[tuple[str, int]]:
    rows = run_query(out, "SELECT source, count(*) FROM battery GROUP BY source, log ORDER BY 1, 2").rows
    return [(str(s), int(n)) for s, n in rows]


def _export(capsys: pytest.CaptureFixture[str], log: Path, out: Path) -> tuple[int, str]:
    code = main(["export", str(log), "-o", str(out), "--message", "uorb.BatteryStatus"])
    return code, capsys.readouterr().err


def test_a_grown_log_replaces_its_earlier_export(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log, out = tmp_path / "flight.jsonl", tmp_path / "ds"
    log.write_text(_records(0, 10), encoding="utf-8")
    assert _export(capsys, log, out)[0] == 0
    (first,) = [p.stem for p in (out / LOGS).glob("*.json")]
    log.write_text(_records(0, 10) + _records(10, 5), encoding="utf-8")  # downloaded again, longer
    code, err = _export(capsys, log, out)
    assert code == 0
    assert f"replaces log {first}, its earlier export (the file has grown)" in err
    assert _flights(out) == [("flight.jsonl", 15)]
    assert first not in {p.stem for p in (out / LOGS).glob("*.json")}  # retired, files and all
    assert not any(first in f for files in committed(out).values() for f in files)
    assert sorted(p.name for p in out.rglob("*.parquet")) == sorted(Path(f).name for f in committed(out)["battery"])


def test_same_name_other_start_is_another_flight(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ds"
    day1, day2 = tmp_path / "day1", tmp_path / "day2"
    day1.mkdir(), day2.mkdir()
    (day1 / "flight.jsonl").write_text(_records(0, 10), encoding="utf-8")
    (day2 / "flight.jsonl").write_text(_records(0, 12, volts=16.0), encoding="utf-8")
    assert _export(capsys, day1 / "flight.jsonl", out)[0] == 0
    code, err = _export(capsys, day2 / "flight.jsonl", out)
    assert code == 0 and "replaces" not in err
    assert _flights(out) == [("flight.jsonl", 10), ("flight.jsonl", 12)]


def test_a_stop_between_the_commit_and_the_removal_hides_the_old_log_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log, out = tmp_path / "flight.jsonl", tmp_path / "ds"
    log.write_text(_records(0, 10), encoding="utf-8")
    options = ExportOptions(out=out, message="uorb.BatteryStatus")
    export_logs([str(log)], options)
    log.write_text(_records(0, 20), encoding="utf-8")

    def stopped(out: Path, log: str) -> None:
        raise KeyboardInterrupt  # the process stops right after the new marker's rename

    monkeypatch.setattr(engine, "retire", stopped)
    with pytest.raises(KeyboardInterrupt):
        export_logs([str(log)], options)
    assert _flights(out) == [("flight.jsonl", 20)]  # readers already see one flight
    assert len(list((out / LOGS).glob("*.json"))) == 2
    monkeypatch.undo()
    export_logs([str(log)], options)  # the next run's start removes what the stop left
    assert len(list((out / LOGS).glob("*.json"))) == 1
    assert _flights(out) == [("flight.jsonl", 20)]


def test_a_kill_at_any_step_of_a_grown_logs_export_leaves_one_flight(tmp_path: Path) -> None:
    """kill -9 before each file-system step of the replacing export, in turn: the dataset reads the earlier flight
    or the grown one (never both, never none), and the next run ends with the grown one and no leftovers."""
    from test_export_commit import _driver, leftovers

    log, base = tmp_path / "flight.jsonl", tmp_path / "base"
    log.write_text(_records(0, 10), encoding="utf-8")
    run = ["export", "-q", "-o", "{out}", str(log), "--message", "uorb.BatteryStatus"]
    assert main([a.format(out=base) for a in run]) == 0
    log.write_text(_records(0, 15), encoding="utf-8")
    counted = tmp_path / "counted"
    shutil.copytree(base, counted)
    done = _driver(tmp_path, 0, [a.format(out=counted) for a in run])
    assert done.returncode == 0, done.stderr
    steps = int(done.stderr.rsplit("STEPS ", 1)[1])
    assert _flights(counted) == [("flight.jsonl", 15)] and steps > 5
    for stop in range(1, steps + 1):
        out = tmp_path / f"kill-{stop}"
        shutil.copytree(base, out)
        assert _driver(tmp_path, stop, [a.format(out=out) for a in run]).returncode == -9
        assert _flights(out) in ([("flight.jsonl", 10)], [("flight.jsonl", 15)]), f"step {stop}"
        assert main([a.format(out=out) for a in run]) == 0
        assert _flights(out) == [("flight.jsonl", 15)] and leftovers(out) == set(), f"step {stop}"
        assert len(list((out / LOGS).glob("*.json"))) == 1, f"step {stop}"
