"""A log that grew between runs (a tlog downloaded again with more frames, a JSON Lines file appended to) is one
flight: its new export replaces the earlier one, in one atomic step, with a line saying so; a file of the same
name whose start differs is another flight."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.apps.export import engine
from codegen.apps.export.engine import ExportOptions, export_logs
from codegen.apps.export.manifest import LOGS, committed
from codegen.apps.fleet_query import run_query
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
