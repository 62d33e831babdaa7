"""battgen export --failsafe: each log's replay through the battery failsafe, compared event for
event with ``battgen failsafe --json`` on the same log and parameters (a DataFlash .bin written from
its FMT records, a tlog packed by pymavlink, a real PX4 ULog); the flights view's failsafe columns;
incremental runs; the views from plain DuckDB."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import duckdb
import pyarrow.parquet as pq
import pytest
from fleet_samples import LOGS, jsonl, needs_logs

from codegen.apps.export.query import run_query
from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cli"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from test_failsafe_replays import PARAMS, write_bin, write_tlog

# the columns of the events table and the keys of battgen failsafe --json that must agree
SAME = {
    "replay_t": "t",
    "instance": "battery",
    "level": "level",
    "cause": "cause",
    "value": "value",
    "threshold": "threshold",
    "action": "action",
    "action_code": "action_code",
    "executed": "executed",
    "outcome": "outcome",
    "priority": "priority",
    "statustext": "ardupilot_text",
    "vehicle_type": "vehicle",
}


def _reference(capsys: pytest.CaptureFixture[str], *args: str) -> list[dict[str, Any]]:
    assert main(["failsafe", "--json", *args]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


def _export(capsys: pytest.CaptureFixture[str], out: Path, *args: str) -> str:
    code = main(["export", "-o", str(out), *args])
    err = capsys.readouterr().err
    assert code == 0, err
    return err


def _events(out: Path, source: str) -> list[dict[str, Any]]:
    """The failsafe events of the log exported from ``source``, as mappings."""
    result = run_query(
        out,
        "SELECT * FROM failsafe_events WHERE log IN (SELECT log FROM battery WHERE source = "
        f"'{source}') ORDER BY replay_t, instance",
    )
    return [dict(zip(result.columns, row, strict=True)) for row in result.rows]


def _params(tmp_path: Path, values: dict[str, float], name: str = "rover.param") -> Path:
    path = tmp_path / name
    path.write_text("".join(f"{k},{v}\n" for k, v in values.items()), encoding="utf-8")
    return path


def test_events_are_battgen_failsafes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    params = _params(tmp_path, PARAMS)
    logs = [write_bin(tmp_path / "flight.bin"), write_tlog(tmp_path / "flight.tlog")]
    out = tmp_path / "ds"
    _export(capsys, out, *map(str, logs), "--failsafe", str(params))
    for log in logs:
        reference = _reference(capsys, "--params", str(params), str(log))
        ours = _events(out, log.name)
        assert len(ours) == len(reference) == 3
        for mine, theirs in zip(ours, reference, strict=True):
            assert {k: mine[k] for k in SAME} == {k: theirs[v] for k, v in SAME.items()}
            assert mine["battery"] == theirs["battery"] - 1  # the table's 0-based battery
            # on the battery table's clock: the record that caused it is at the same t
            volts = run_query(
                out,
                f"SELECT pack_voltage FROM battery WHERE log = '{mine['log']}' AND battery = {mine['battery']} "
                f"AND t = {mine['t']}",
            ).rows
            assert len(volts) == 1
            if mine["cause"] == "voltage":
                assert volts[0][0] == pytest.approx(mine["value"])
    tlog_times = [e["time"].timestamp() for e in _events(out, "flight.tlog")]
    assert tlog_times == pytest.approx([1_700_000_000 + t for t in (15.2, 35.2, 45.2)])  # the tlog's own stamps
    assert all(e["time"] is None for e in _events(out, "flight.bin"))  # a DataFlash log without GPS time
    flights = run_query(
        out,
        "SELECT source, battery, failsafe_level, failsafe_events, failsafe_first_low, failsafe_first_critical, "
        "failsafe_outcome FROM flights ORDER BY source, battery",
    ).rows
    # battery 1 (0 here): LOW at 15.2 s (Hold), CRITICAL at 35.2 s (RTL, outranked); battery 2: LOW at 45.2 s
    expected = [(0, "CRITICAL", 2, 15.2, 35.2, "hold"), (1, "LOW", 1, 45.2, None, "disarm")]
    assert flights == [("flight.bin", *e) for e in expected] + [("flight.tlog", *e) for e in expected]
    packs = run_query(out, "SELECT sum(failsafe_events) FROM packs").rows
    assert packs == [(6,)]


def test_own_parameters_and_logs_without_any(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--failsafe log``: a DataFlash log replays with its PARM records (as battgen failsafe does
    without --params); a tlog and a JSON Lines file are not replayed, and the flights view says so
    with nulls (not with zero events)."""
    out = tmp_path / "ds"
    logs = [write_bin(tmp_path / "flight.bin"), write_tlog(tmp_path / "flight.tlog"), jsonl(tmp_path / "b.jsonl")]
    _export(capsys, out, *map(str, logs), "--failsafe", "log")
    reference = _reference(capsys, str(logs[0]))
    assert [(e["replay_t"], e["statustext"]) for e in _events(out, "flight.bin")] == [
        (e["t"], e["ardupilot_text"]) for e in reference
    ]
    rows = run_query(out, "SELECT source, failsafe_level, failsafe_events FROM flights ORDER BY source, battery").rows
    assert rows == [
        ("b.jsonl", None, None),
        ("flight.bin", "CRITICAL", 2),
        ("flight.bin", "LOW", 1),
        ("flight.tlog", None, None),
        ("flight.tlog", None, None),
    ]
    notes = {json.loads(p.read_text())["source"]: json.loads(p.read_text())["notes"] for p in out.glob("logs/*.json")}
    assert notes["flight.tlog"] == [
        "failsafe not replayed: the log carries no ArduPilot parameters of its own (a DataFlash log's PARM, a "
        "tlog's PARAM_VALUE; give --failsafe PARAMS)"
    ]
    assert notes["b.jsonl"] == ["failsafe not replayed: a JSON Lines file is no flight log battgen failsafe reads"]


def test_incremental_runs_replay_again_only_for_new_parameters(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ds"
    log = str(write_bin(tmp_path / "flight.bin"))
    _export(capsys, out, log)  # no replay: empty failsafe views, null columns
    assert run_query(out, "SELECT count(*) FROM failsafe_events").rows == [(0,)]
    assert run_query(out, "SELECT DISTINCT failsafe_events FROM flights").rows == [(None,)]
    assert "1 exported" in _export(capsys, out, log, "--failsafe", str(_params(tmp_path, PARAMS)))
    assert run_query(out, "SELECT count(*) FROM failsafe_events").rows == [(3,)]
    assert "1 already in the dataset" in _export(capsys, out, log, "--failsafe", str(tmp_path / "rover.param"))
    assert "1 already in the dataset" in _export(capsys, out, log)  # no replay asked: the earlier one stays
    stricter = _params(tmp_path, {**PARAMS, "BATT_LOW_VOLT": 11.0, "BATT_LOW_TIMER": 1}, "stricter.param")
    assert "1 exported" in _export(capsys, out, log, "--failsafe", str(stricter))
    events = _events(out, "flight.bin")
    first = events[0]
    assert (first["replay_t"], first["level"], first["parameters"].split(" ")[0]) == (11.2, "LOW", "stricter.param")
    assert len(list((out / "battery").iterdir())) == 1  # replaced, not doubled
    assert run_query(out, "SELECT count(*) FROM battery").rows == [(600,)]


def test_views_from_plain_duckdb_and_metadata(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ds"
    _export(capsys, out, str(write_bin(tmp_path / "flight.bin")), "--failsafe", str(_params(tmp_path, PARAMS)))
    con = duckdb.connect()
    con.execute(f"SET file_search_path = '{out}'")
    con.execute((out / "views.sql").read_text(encoding="utf-8"))
    assert con.sql("SELECT failsafe_level FROM flights ORDER BY battery").fetchall() == [("CRITICAL",), ("LOW",)]
    schema = pq.read_schema(next((out / "failsafe").glob("*/events-*.parquet")))
    assert schema.field("t").metadata[b"unit"] == b"s"
    assert b"STATUSTEXT" in schema.field("statustext").metadata[b"doc"]


@needs_logs
def test_real_ulog_events_on_the_battery_clock(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A real PX4 log: the replay runs on the battery table's clock (seconds since the log's start), so the
    event sits on the battery record that caused it, at the time ``battgen failsafe`` prints."""
    log = next(p for p in LOGS if p.name == "sample_px4_events.ulg")
    params = _params(tmp_path, {"BATT_LOW_VOLT": 16.1, "BATT_LOW_TIMER": 1, "BATT_FS_LOW_ACT": 2}, "px4.param")
    out = tmp_path / "ds"
    _export(capsys, out, str(log), "--failsafe", str(params))
    reference = _reference(capsys, "--params", str(params), str(log))
    ours = _events(out, log.name)
    assert [{k: e[k] for k in SAME} for e in ours] == [{k: r[v] for k, v in SAME.items()} for r in reference]
    assert [(e["level"], e["outcome"]) for e in ours] == [("LOW", "hold")]
    row = run_query(
        out, f"SELECT pack_voltage, t FROM battery WHERE battery = {ours[0]['battery']} AND t = {ours[0]['t']}"
    ).rows
    assert row[0][0] == pytest.approx(ours[0]["value"], rel=1e-6)
    assert ours[0]["t"] == ours[0]["replay_t"] == row[0][1]  # one clock


def test_bad_failsafe_parameters_are_clear_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = str(write_bin(tmp_path / "flight.bin"))
    assert main(["export", "-o", str(tmp_path / "ds"), log, "--failsafe", str(tmp_path / "none.param")]) == 2
    assert "none.param" in capsys.readouterr().err
    empty = _params(tmp_path, {"FOO": 1.0}, "foo.param")
    assert main(["export", "-o", str(tmp_path / "ds"), log, "--failsafe", str(empty)]) == 2
    assert "no BATT*_ parameter" in capsys.readouterr().err
    assert main(["export", "-o", str(tmp_path / "ds"), log, "--failsafe", "log", "--vehicle", "boat"]) == 2
    assert "expected a vehicle among" in capsys.readouterr().err
    assert not (tmp_path / "ds").exists()


def test_options_travel_to_workers(tmp_path: Path) -> None:
    """The replay's parameters are read once, on the caller's side, and go to worker processes and
    Dask workers inside the (pickled) options: no worker needs the parameter file."""
    import pickle

    from codegen.apps.export.engine import ExportOptions
    from codegen.apps.export.failsafe_tables import failsafe_options

    replay = failsafe_options(str(_params(tmp_path, PARAMS)), "rover")
    options = ExportOptions(tmp_path / "ds", failsafe=replay, partition="day")
    (tmp_path / "rover.param").unlink()
    back = pickle.loads(pickle.dumps(options))
    assert back == options and back.failsafe is not None
    assert back.failsafe.params == PARAMS and back.failsafe.key.endswith("|vehicle=rover|firmware=detected")


# PX4's rows: the same keys but ArduPilot's priority and vehicle; its notification is battgen failsafe's firmware_text
PX4_SAME = {k: v for k, v in SAME.items() if k not in ("priority", "vehicle_type")} | {"statustext": "firmware_text"}


def test_a_px4_log_replays_px4s_failsafe_as_battgen_failsafe_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A real PX4 flight reaching LOW, CRITICAL and EMERGENCY: ``--failsafe log`` replays PX4's own failsafe
    with the log's BAT_*/COM_* parameters (battgen failsafe's choice for a ULog), event for event as
    ``battgen failsafe --json`` prints them, on the battery table's clock."""
    from shared_data import require, shared

    log = require(shared("corpus", "realworld3", "ulog", "fsyrh_log_61_2024-2-6-16-27-02.ulg"))
    out = tmp_path / "ds"
    _export(capsys, out, str(log), "--failsafe", "log")
    reference = _reference(capsys, str(log))
    ours = _events(out, log.name)
    assert [{k: e[k] for k in PX4_SAME} for e in ours] == [{k: r[v] for k, v in PX4_SAME.items()} for r in reference]
    assert [e["level"] for e in ours] == ["LOW", "CRITICAL", "EMERGENCY"]
    assert {e["vehicle_type"] for e in ours} == {"px4"} and {e["priority"] for e in ours} == {None}
    for e in ours:  # the state of charge that crossed is the battery table's, at the same t
        soc = run_query(
            out, f"SELECT state_of_charge FROM battery WHERE battery = {e['battery']} AND t = {e['t']}"
        ).rows
        assert soc and soc[0][0] == pytest.approx(e["value"], rel=1e-6)
    replays = run_query(out, "SELECT instance, level, vehicle_type, readings > 0 FROM failsafe_replays").rows
    assert replays == [(1, "EMERGENCY", "px4", True)]
    # ArduPilot's BATT_ parameters still choose ArduPilot's failsafe for the same log, as battgen failsafe does
    params = _params(tmp_path, {"BATT_LOW_VOLT": 16.1, "BATT_LOW_TIMER": 1, "BATT_FS_LOW_ACT": 2}, "ap.param")
    _export(capsys, tmp_path / "ap", str(log), "--failsafe", str(params))
    assert "px4" not in {e["vehicle_type"] for e in _events(tmp_path / "ap", log.name)}
    replayed = run_query(tmp_path / "ap", "SELECT vehicle_type FROM failsafe_replays").rows
    assert replayed and all(v != "px4" for (v,) in replayed)
    _export(capsys, tmp_path / "forced", str(log), "--failsafe", str(params), "--firmware", "px4")
    assert [e["level"] for e in _events(tmp_path / "forced", log.name)] == ["LOW", "CRITICAL", "EMERGENCY"]
