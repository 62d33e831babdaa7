"""The PX4 failsafe benchmark runs on one real log, both sides agreeing (its figures are printed, not asserted)."""

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
    (only,) = bench.run([log], rounds=1).values()  # raises where the two sides' events differ
    assert set(only) == {"ours", "peer", "ratio", "events"} and only["ours"] > 0 and only["peer"] > 0
    assert "pyulog loop / battgen" in capsys.readouterr().out
