"""The report-reading benchmark still runs (a one-minute synthetic flight; the times are not checked)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT


def test_bench_report_read_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_report_read")
    finally:
        sys.path.remove(str(ROOT))
    results = bench.run(seconds=60, real=False)
    (figures,) = results.values()
    assert figures["records"] == 1200  # 60 s at 10 Hz, two packs
    assert figures["before_s"] > 0 and figures["after_s"] > 0
    assert "ratio" in capsys.readouterr().out
