"""benchmarks/bench_c_speed.py still runs (tiny iteration counts; the figures are not checked): ours and
mavgen's C built from the same XML, timed on the same BATTERY_STATUS (the program refuses to time
frames whose payloads differ)."""

from __future__ import annotations

import importlib.util
import shutil
import sys

import pytest
from conftest import ROOT


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_bench_c_speed_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_c_speed", ROOT / "benchmarks" / "bench_c_speed.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_c_speed"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--number", "200"])
    finally:
        del sys.modules["bench_c_speed"]
    expected = {"encode_ours", "encode_mavgen", "decode_ours", "decode_mavgen", "dronecan_info_decode"}
    assert expected <= set(results)
    assert all(results[k] > 0 for k in expected)
    assert "mavgen" in capsys.readouterr().out
