"""benchmarks/bench_mavlink.py still runs (tiny iteration counts; the figures are not checked)."""

from __future__ import annotations

import importlib.util
import sys

import pytest
from conftest import ROOT


def test_bench_mavlink_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_mavlink", ROOT / "benchmarks" / "bench_mavlink.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_mavlink"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--number", "3", "--records", "50"])
    finally:
        del sys.modules["bench_mavlink"]
    assert all(value > 0 for value in results.values())
    assert {"pack_ours", "parse_ours", "parse_pymavlink", "decode_payload_floor", "batch_struct_rps"} <= set(results)
    assert "pymavlink" in capsys.readouterr().out
