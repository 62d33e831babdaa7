"""battgen export --partition day: ``<table>/day=YYYY-MM-DD/log=<id>/`` from each log's UTC time of
day (Hive's null partition where a log has none); DuckDB and pyarrow read both layouts back the same,
DuckDB prunes by day, incremental runs skip, and one dataset keeps one layout."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import duckdb
import pyarrow.dataset as pads
import pytest
from fleet_samples import jsonl, tlog

from codegen.apps.export.query import run_query
from codegen.apps.export.views import views_sql
from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cli"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from test_failsafe_replays import PARAMS, write_bin, write_tlog

FLIGHTS = "SELECT source, battery, records, min_voltage, failsafe_level FROM flights ORDER BY source, battery"


def _logs(tmp_path: Path) -> list[Path]:
    # tlogs carry UTC times (2023-11-14 and 2023-11-14 again); the .bin and the JSON Lines file have none
    return [
        tlog(tmp_path / "a.tlog"),
        write_tlog(tmp_path / "flight.tlog"),
        write_bin(tmp_path / "flight.bin"),
        jsonl(tmp_path / "b.jsonl"),
    ]


def _export(capsys: pytest.CaptureFixture[str], out: Path, logs: list[Path], *args: str) -> tuple[int, str]:
    params = out.parent / "rover.param"
    params.write_text("".join(f"{k},{v}\n" for k, v in PARAMS.items()), encoding="utf-8")
    code = main(["export", "-o", str(out), *map(str, logs), "--failsafe", str(params), *args])
    return code, capsys.readouterr().err


def test_day_layout_reads_back_as_the_log_layout(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    logs = _logs(tmp_path)
    by_log, by_day = tmp_path / "by_log", tmp_path / "by_day"
    assert _export(capsys, by_log, logs)[0] == 0
    assert _export(capsys, by_day, logs, "--partition", "day")[0] == 0
    days = sorted(p.name for p in (by_day / "battery").iterdir())
    assert days == ["day=2023-11-14", "day=__HIVE_DEFAULT_PARTITION__"]
    assert len(list((by_day / "battery" / "day=__HIVE_DEFAULT_PARTITION__").iterdir())) == 2  # .bin, .jsonl
    assert sorted({p.parent.parent.name for p in (by_day / "failsafe").rglob("events-*.parquet")}) == [
        "day=2023-11-14",
        "day=__HIVE_DEFAULT_PARTITION__",
    ]
    # the same table and views either way
    assert run_query(by_day, FLIGHTS).rows == run_query(by_log, FLIGHTS).rows
    columns = "log, battery, t, pack_voltage"
    query = f"SELECT {columns} FROM battery ORDER BY {columns}"
    assert run_query(by_day, query).rows == run_query(by_log, query).rows
    days_read = run_query(by_day, "SELECT DISTINCT day FROM battery ORDER BY day NULLS LAST").rows
    assert [str(d) if d else None for (d,) in days_read] == ["2023-11-14", None]
    # views.sql from plain DuckDB, in each folder
    for out in (by_log, by_day):
        con = duckdb.connect()
        con.execute(f"SET file_search_path = '{out}'")
        con.execute((out / "views.sql").read_text(encoding="utf-8"))
        assert con.sql(FLIGHTS).fetchall() == run_query(by_log, FLIGHTS).rows
    # pyarrow's Hive partitioning reads the null day as null too
    table = pads.dataset(by_day / "battery", partitioning="hive").to_table(columns=["day", "source"])
    assert {(r["day"], r["source"]) for r in table.to_pylist()} == {
        ("2023-11-14", "a.tlog"),
        ("2023-11-14", "flight.tlog"),
        (None, "flight.bin"),
        (None, "b.jsonl"),
    }


def test_duckdb_prunes_days(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A filter on ``day`` reads only that day's files (DuckDB's own account in EXPLAIN ANALYZE)."""
    out = tmp_path / "ds"
    assert _export(capsys, out, _logs(tmp_path), "--partition", "day")[0] == 0
    con = duckdb.connect()
    con.execute(views_sql(out))
    query = "SELECT count(*) FROM battery WHERE day = DATE '2023-11-14'"
    assert con.sql(query).fetchall() == [(6 + 600,)]
    plan = "\n".join(str(row[1]) for row in con.sql("EXPLAIN ANALYZE " + query).fetchall())
    scanned = re.search(r"Scanning Files: (\d+)/(\d+)", plan)
    if scanned is None:
        pytest.skip(f"DuckDB {duckdb.__version__} does not report the files it scans")
    assert scanned.groups() == ("2", "4")  # the two tlogs of that day, of four logs


def test_incremental_and_one_layout_per_dataset(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ds"
    logs = _logs(tmp_path)
    assert _export(capsys, out, logs[:2], "--partition", "day")[0] == 0
    code, err = _export(capsys, out, logs, "--partition", "day")
    assert code == 0 and "2 exported" in err and "2 already in the dataset" in err
    code, err = _export(capsys, out, logs)  # the default, by log: refused, nothing written
    assert code == 2
    assert "the dataset is partitioned by day; give --partition day or a new folder" in err
    assert not (out / "battery" / "log=").exists() and len(list((out / "logs").glob("*.json"))) == 4
