"""battgen export and battgen query on the command line: exit codes, the summary, the formats."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest
from fleet_samples import jsonl, tlog

from codegen.cli.main import main


def test_export_then_query(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ds"
    logs = tmp_path / "logs"
    logs.mkdir()
    tlog(logs / "a.tlog")
    jsonl(logs / "b.jsonl")
    assert main(["export", str(logs), "-o", str(out), "--raw"]) == 0
    err = capsys.readouterr().err
    assert "2 logs: 2 exported (10 rows), 0 already in the dataset, 0 unreadable" in err
    assert main(["export", str(logs), "-o", str(out)]) == 0
    assert "2 already in the dataset" in capsys.readouterr().err
    assert main(["query", str(out), "SELECT source, records FROM flights ORDER BY source"]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[0].split() == ["source", "records"] and "a.tlog" in text and "(2 rows)" in text
    assert (
        main(
            [
                "query",
                str(out),
                "SELECT source, cell_voltages FROM battery ORDER BY source, t LIMIT 1",
                "--format",
                "json",
            ]
        )
        == 0
    )
    data = json.loads(capsys.readouterr().out)
    assert data[0]["source"] == "a.tlog" and data[0]["cell_voltages"] == pytest.approx([4.1, 4.09, 4.08])
    assert main(["query", str(out), "SELECT pack, flights FROM packs ORDER BY pack", "--format", "csv"]) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert rows[0] == ["pack", "flights"] and len(rows) == 3
    target = tmp_path / "f.parquet"
    assert main(["query", str(out), "SELECT * FROM flights", "--format", "parquet", "-o", str(target)]) == 0
    assert target.is_file() and "2 rows" in capsys.readouterr().err


def test_bad_logs_exit_1_and_are_listed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "bad.ulg").write_bytes(b"junk")
    good = jsonl(tmp_path / "g.jsonl")
    assert (
        main(
            ["export", str(tmp_path / "bad.ulg"), str(good), str(tmp_path / "missing.tlog"), "-o", str(tmp_path / "ds")]
        )
        == 1
    )
    err = capsys.readouterr().err
    assert "bad.ulg" in err and "missing.tlog" in err and "1 exported (4 rows)" in err and "2 unreadable" in err
    assert "Traceback" not in err


def test_nothing_to_read_and_bad_queries_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    empty = tmp_path / "none"
    empty.mkdir()
    assert main(["export", str(empty), "-o", str(tmp_path / "ds")]) == 2
    assert "no logs to export" in capsys.readouterr().err
    assert main(["query", str(tmp_path / "ds"), "SELECT 1"]) == 2
    assert "no exported logs" in capsys.readouterr().err
    jsonl(tmp_path / "g.jsonl")
    assert main(["export", str(tmp_path / "g.jsonl"), "-o", str(tmp_path / "ds"), "-q"]) == 0
    assert main(["query", str(tmp_path / "ds"), "SELECT nope FROM battery"]) == 2
    err = capsys.readouterr().err
    assert "query failed" in err and '"nope" not found' in err  # DuckDB's sentences, on one line
    assert err.count("\n") == 1 and "\\x0a" not in err and "LINE 1" not in err
    assert main(["query", str(tmp_path / "ds"), "SELECT 1", "--format", "parquet"]) == 2
    assert "-o FILE" in capsys.readouterr().err
