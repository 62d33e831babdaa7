"""The start-up benchmark still runs (a real PX4 log of the shared data; the figures are not checked)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT

LOG = ROOT.parent / "shared" / "data" / "ulog" / "sample_px4_events.ulg"


@pytest.mark.skipif(not LOG.is_file(), reason="needs ../shared/data/ulog/sample_px4_events.ulg")
def test_bench_startup_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_startup")
    finally:
        sys.path.remove(str(ROOT))
    figures = bench.run(LOG)
    assert all(figures[k] > 0 for k in ("catalog_ours_s", "catalog_jsonschema_s", "help_ours_s", "export_ours_s"))
    out = capsys.readouterr().out
    assert "bundled_catalog()" in out and "battgen export" in out
