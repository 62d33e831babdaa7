"""benchmarks/bench_c_convert.py still runs (tiny iteration counts; the figures are not checked): the C
converters and the Python ones on the same DroneCAN BatteryInfo + Aux, both policies."""

from __future__ import annotations

import importlib.util
import shutil
import sys

import pytest
from conftest import ROOT


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_bench_c_convert_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_c_convert", ROOT / "benchmarks" / "bench_c_convert.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_c_convert"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--number", "20"])
    finally:
        del sys.modules["bench_c_convert"]
    assert set(results) == {"c_strict", "c_px4", "python_strict", "python_px4"}
    assert all(v > 0 for v in results.values())
    assert "ns/record" in capsys.readouterr().out
