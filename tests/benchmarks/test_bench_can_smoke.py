"""The CAN capture benchmark still runs (a tiny capture; the figures are not checked)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT

pytest.importorskip("dronecan")


def test_bench_can_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_can")
    finally:
        sys.path.remove(str(ROOT))
    figures = bench.run(transfers=40)
    assert figures["frames"] > 0 and figures["ours_fps"] > 0 and figures["ref_fps"] > 0
    assert "frames/s" in capsys.readouterr().out
