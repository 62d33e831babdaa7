"""benchmarks/bench_ulog.py still runs (tiny iteration counts; the figures are not checked)."""

from __future__ import annotations

import importlib.util
import sys

import pytest
from conftest import ROOT


def test_bench_ulog_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_ulog", ROOT / "benchmarks" / "bench_ulog.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_ulog"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--number", "3", "--records", "40", "--repeat", "1"])
    finally:
        del sys.modules["bench_ulog"]
    assert all(value > 0 for value in results.values())
    assert results["synthetic_records"] == 40
    assert {"synthetic_pyulog_rps", "decode_floor", "batch_numpy_rps", "batch_struct_rps", "write_rps"} <= set(results)
    assert "pyulog" in capsys.readouterr().out
