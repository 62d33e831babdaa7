"""benchmarks/bench_convert.py still runs (tiny record counts; the figures are not checked)."""

from __future__ import annotations

import importlib.util
import sys

import pytest
from conftest import ROOT


def test_bench_convert_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_convert", ROOT / "benchmarks" / "bench_convert.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_convert"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--records", "20", "--repeat", "1", "--cli-records", "50", "--rounds", "1"])
    finally:
        del sys.modules["bench_convert"]
    assert all(value > 0 for value in results.values())
    assert {"dronecan->uorb px4", "uorb->mavlink strict report", "cli jsonl dronecan->mavlink px4"} <= set(results)
    out = capsys.readouterr().out
    assert "records/s" in out and "outputs: 50 records, equal value for value" in out
