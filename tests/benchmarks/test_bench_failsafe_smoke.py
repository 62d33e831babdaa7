"""The failsafe benchmark runs on a tiny repeated log (its figures are printed, not asserted)."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data" / "ulog"


def test_bench_failsafe_smoke(capsys: pytest.CaptureFixture[str]) -> None:
    if not (SHARED / "sample_px4_events.ulg").is_file():
        if os.environ.get("CI"):
            pytest.fail(f"{SHARED} is missing")
        pytest.skip(f"{SHARED} is missing")
    spec = importlib.util.spec_from_file_location("bench_failsafe", ROOT / "benchmarks" / "bench_failsafe.py")
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    results = bench.run(records=500, real=False)
    (only,) = results.values()
    assert set(only) == {"export", "export_failsafe", "report", "replay", "per_sample_replay"}
    assert all(v > 0 for v in only.values())
    assert "500 battery_status records" in capsys.readouterr().out
