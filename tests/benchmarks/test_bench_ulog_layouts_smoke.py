"""benchmarks/bench_ulog_layouts.py still runs (a tiny repeated log; the figures are not checked)."""

from __future__ import annotations

import importlib.util
import os
import sys

import pytest
from conftest import ROOT


def test_bench_ulog_layouts_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_ulog_layouts", ROOT / "benchmarks" / "bench_ulog_layouts.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_ulog_layouts"] = module
    try:
        spec.loader.exec_module(module)
        if not module.DEFAULT_LOG.is_file():
            if os.environ.get("CI"):
                pytest.fail(f"missing {module.DEFAULT_LOG}")
            pytest.skip(f"missing {module.DEFAULT_LOG}")
        results = module.main(["--records", "500"])
    finally:
        del sys.modules["bench_ulog_layouts"]
    assert results["records"] >= 500
    assert results["battgen_rps"] > 0 and results["hand_rps"] > 0
    assert "to_parquet" in capsys.readouterr().out
