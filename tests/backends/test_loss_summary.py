"""LossReport.summary() and ``battgen convert --report-summary``: the compact loss report."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main
from generated.convert import LossReport
from generated.convert.dronecan_uorb import dronecan_to_uorb
from generated.dronecan.uavcan.equipment.power import BatteryInfo


def test_summary_groups_entries_by_kind_and_message() -> None:
    report = LossReport()
    assert report.summary() == "nothing lost"
    dronecan_to_uorb(BatteryInfo(voltage=12.0), report=report)
    text = report.summary()
    lines = text.splitlines()
    assert lines[0].startswith("unknown (") and "uorb.BatteryStatus: " in lines[0]
    unknown = report.fields("unknown")
    assert lines[0].startswith(f"unknown ({len(unknown)}):")
    assert all(f.rsplit(".", 1)[1] in lines[0] for f in unknown)
    assert len(text) < len(json.dumps(report.to_dict())) / 2
    report.clamped("m.x", "too big")
    assert report.summary().splitlines()[-1] == "clamped (1): m: x (too big)"


def test_cli_report_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text(json.dumps({"voltage": 12.6, "temperature": 298.15}) + "\n")
    assert main(["convert", "--from", "dronecan", "--to", "uorb", "--report-summary", str(src)]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["record"]["voltage_v"] == pytest.approx(12.6, rel=1e-6)
    assert isinstance(record["loss"], str) and record["loss"].startswith("unknown (")
    # --report keeps its meaning: every entry
    assert main(["convert", "--from", "dronecan", "--to", "uorb", "--report", str(src)]) == 0
    assert isinstance(json.loads(capsys.readouterr().out)["loss"], list)
