"""The DroneCAN benchmark still runs (tiny iteration counts; the figures are not checked)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT

pytest.importorskip("dronecan")


def test_bench_dronecan_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_dronecan")
    finally:
        sys.path.remove(str(ROOT))
    times = bench.run(number=20, ref_number=2)
    assert set(times) == {"ours_encode", "ref_encode", "ours_decode", "ref_decode", "floor_decode"}
    assert all(t > 0 for t in times.values())
    assert "build+encode" in capsys.readouterr().out
