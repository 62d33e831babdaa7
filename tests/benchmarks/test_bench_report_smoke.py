"""The report benchmark still runs (a one-minute flight; the figures are not checked)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT

pytest.importorskip("plotly")
pytest.importorskip("pyulog")


def test_bench_report_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_report")
    finally:
        sys.path.remove(str(ROOT))
    figures = bench.run(seconds=60)
    assert figures["ours_s"] > 0 and figures["hand_s"] > 0
    assert "pyulog+plotly" in capsys.readouterr().out
