"""``battgen convert --policy px4`` over a stream of DroneCAN BatteryInfo records: PX4's uavcan bridge
integrates the discharged charge from message to message (Battery::sumDischarged), so the converter
input ``discharged_mah_before`` is carried from each record's result to the next."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main


def _run(tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> list[dict[str, object]]:
    records = tmp_path / "info.jsonl"
    records.write_text("".join(json.dumps({"current": c, "voltage": 16.0}) + "\n" for c in (36.0, 36.0, -72.0)))
    code = main(["convert", "--from", "dronecan", "--to", "uorb", "--policy", "px4", *extra, str(records)])
    assert code == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


def test_discharged_mah_integrates_across_records(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = _run(tmp_path, capsys, "--set", "dt_s=1")
    # |current| * 1000 mA * 1 s / 3600 s/h: 10 mAh per 36 A second, a charge counted as a discharge (fabsf)
    assert [r["discharged_mah"] for r in out] == [10.0, 20.0, 40.0]


def test_a_given_total_is_not_overridden(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = _run(tmp_path, capsys, "--set", "dt_s=1", "--set", "discharged_mah_before=100")
    assert [r["discharged_mah"] for r in out] == [110.0, 110.0, 120.0]


def test_without_dt_nothing_integrates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert [r["discharged_mah"] for r in _run(tmp_path, capsys)] == [0.0, 0.0, 0.0]
