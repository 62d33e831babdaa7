"""The PX4 failsafe benchmark runs on one real log (its figures are printed, not asserted)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from shared_data import REAL_LOGS, require

ROOT = Path(__file__).resolve().parents[2]


def test_bench_px4_failsafe_smoke(capsys: pytest.CaptureFixture[str]) -> None:
    log = require(REAL_LOGS / "sample_px4_events.ulg")
    spec = importlib.util.spec_from_file_location("bench_px4_failsafe", ROOT / "benchmarks" / "bench_px4_failsafe.py")
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    (only,) = bench.run([log], repeat=1).values()
    assert set(only) == {"ours", "replay", "pyulog"} and all(v > 0 for v in only.values())
    assert "ours / pyulog" in capsys.readouterr().out
