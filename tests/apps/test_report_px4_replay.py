"""A PX4 log's report replays PX4's own battery failsafe (codegen/apps/failsafe/px4_replay.py), as ``battgen
failsafe`` does on the same log: the same events at the same times, on a real log that goes low, critical and
emergency."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main
from tests.shared_data import require, shared

LOG = shared("corpus", "realworld3", "ulog", "fsyrh_log_61_2024-2-6-16-27-02.ulg")


def test_the_report_shows_the_px4_replay_of_battgen_failsafe(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = require(LOG)
    assert main(["failsafe", str(log), "--json"]) == 0
    cli = [json.loads(line) for line in capsys.readouterr().out.splitlines() if line.startswith("{")]
    out = tmp_path / "r.json"
    assert main(["report", str(log), "--format", "json", "-o", str(out)]) == 0
    capsys.readouterr()
    (page,) = json.loads(out.read_text(encoding="utf-8"))["inputs"]
    assert page["failsafe_note"].startswith("replayed through PX4's battery failsafe")
    shown = [(e["t"], e["level"]) for b in page["batteries"] for e in b["failsafe_events"]]
    assert [(e["t"], e["level"]) for e in cli] == sorted(shown)
    assert [level for _, level in shown][:3] == ["LOW", "CRITICAL", "EMERGENCY"]
