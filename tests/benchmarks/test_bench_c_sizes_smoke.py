"""benchmarks/bench_c_sizes.py still runs: every message of the C library has code on a Cortex-M4 and
no data (the library keeps no state)."""

from __future__ import annotations

import importlib.util
import os
import shutil
import sys

import pytest
from conftest import ROOT


def test_bench_c_sizes_runs(capsys: pytest.CaptureFixture[str]) -> None:
    if shutil.which("arm-none-eabi-gcc") is None:
        if os.environ.get("CI"):
            pytest.fail("arm-none-eabi-gcc not installed (CI installs it: .ci/run)")
        pytest.skip("arm-none-eabi-gcc not installed")
    spec = importlib.util.spec_from_file_location("bench_c_sizes", ROOT / "benchmarks" / "bench_c_sizes.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_c_sizes"] = module
    try:
        spec.loader.exec_module(module)
        assert module.main([]) == 0
        sizes = module.measure()
    finally:
        del sys.modules["bench_c_sizes"]
    headers = [p for p in (ROOT / "generated" / "c").rglob("*.h") if p.parent.name != "c"]
    assert len([k for k in sizes if k != "(shared)"]) == len(headers)
    assert all(v["code"] > 0 and v["data"] == 0 for v in sizes.values()), sizes
    assert "uorb_BatteryStatus" in capsys.readouterr().out
