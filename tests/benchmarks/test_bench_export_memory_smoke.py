"""benchmarks/bench_export_memory.py still runs, at tiny lengths (the issue's lengths, 1M tlog frames and JSON
Lines records and 10M CAN frames, are the benchmark's own run): every kind exports, and its peak resident size
is printed and far within the 400 MB budget at these lengths."""

from __future__ import annotations

import importlib.util
import sys

import pytest
from conftest import ROOT


def test_bench_export_memory_runs(capsys: pytest.CaptureFixture[str]) -> None:
    path = ROOT / "benchmarks" / "bench_export_memory.py"
    spec = importlib.util.spec_from_file_location("bench_export_memory", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_export_memory"] = module
    try:
        spec.loader.exec_module(module)
        peaks = module.main(["--short", "300", "--long", "3000", "--can-long", "30000"])
    finally:
        del sys.modules["bench_export_memory"]
    assert set(peaks) == {"tlog", "jsonl", "can"}
    assert all(0 < mb < module.BUDGET_MB for both in peaks.values() for mb in both), peaks
    out = capsys.readouterr().out
    assert out.count("within the 400 MB budget") == 3 and "  0\n" in out
