"""An export whose worker process dies: that log is reported with what ended its process, every other
log is exported, views.sql is written and the exit code says some failed (no BrokenProcessPool traceback)."""

from __future__ import annotations

import faulthandler
import json
import os
import signal
from pathlib import Path

import pytest

from codegen.apps.export import engine
from codegen.apps.export.workers import run_alone, run_pooled
from codegen.cli.main import main


def _job(path: str) -> str:
    """A task that dies as a worker can (SIGKILL: the out-of-memory killer; SIGBUS: a mapped file gone)."""
    if "die-kill" in path:
        os.kill(os.getpid(), signal.SIGKILL)
    if "die-bus" in path:
        faulthandler.disable()  # pytest's, inherited: it would print a dump of the stack first
        os.kill(os.getpid(), signal.SIGBUS)
    return f"done {path}"


def _failed(path: str, why: str) -> str:
    return f"failed {path}: {why}"


def test_a_dead_worker_fails_its_own_task_only() -> None:
    paths = [f"log{i}" for i in range(6)] + ["die-kill", "die-bus"] + [f"late{i}" for i in range(4)]
    results = sorted(run_pooled(_job, paths, 2, _failed))
    assert results == sorted(
        [f"done {p}" for p in paths if not p.startswith("die")]
        + [
            "failed die-kill: the export process died (killed by SIGKILL); the other logs went on",
            "failed die-bus: the export process died (killed by SIGBUS); the other logs went on",
        ]
    )


def test_a_task_alone_returns_its_result() -> None:
    assert run_alone(_job, "fine", _failed) == "done fine"


def _dies_for_one(path: str, options: engine.ExportOptions) -> engine.LogResult:
    if Path(path).name == "b.jsonl":
        os.kill(os.getpid(), signal.SIGKILL)
    return _export_one(path, options)


_export_one = engine.export_one


def test_export_jobs_goes_on_past_a_dead_worker(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    for k, name in enumerate("abc"):
        records = [
            {"timestamp": 1_000_000 * (i + 1), "voltage_v": 12.0 - k - i * 0.1, "current_a": 5.0} for i in range(4)
        ]
        (logs / f"{name}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records), encoding="utf-8")
    monkeypatch.setattr(engine, "export_one", _dies_for_one)  # the workers are forked: they see it too
    out = tmp_path / "dataset"
    code = main(["export", str(logs), "-o", str(out), "--jobs", "2", "--quiet", "--message", "uorb.BatteryStatus"])
    err = capsys.readouterr().err
    assert code == 1
    assert "b.jsonl: the export process died (killed by SIGKILL)" in err
    assert "Traceback" not in err and "BrokenProcessPool" not in err
    assert (out / "views.sql").is_file()
    manifests = [p.read_text() for p in out.rglob("*.json") if p.name != "dataset.json"]
    assert sum('"a.jsonl"' in m for m in manifests) == 1 and sum('"c.jsonl"' in m for m in manifests) == 1
    assert not any('"b.jsonl"' in m for m in manifests)
