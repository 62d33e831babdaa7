"""benchmarks/bench_fleet.py still runs on a small fleet (the figures are not checked, the counts are)."""

from __future__ import annotations

import importlib.util
import sys

import pytest
from conftest import ROOT


def test_bench_fleet_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_fleet", ROOT / "benchmarks" / "bench_fleet.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_fleet"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--records", "2000", "--logs", "4", "--log-records", "50", "--repeat", "1", "--no-dask"])
    finally:
        del sys.modules["bench_fleet"]
    assert results["synthetic_records"] == 2000 and results["mixed_records"] == 100
    assert results["jobs_rows"] == 4 * 50 == results["fleet_records"]
    assert results["duckdb_flights_rows"] == 8
    out = capsys.readouterr().out
    assert "hand path" in out and "equal" in out and "DIFFERENT" not in out
