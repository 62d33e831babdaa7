"""benchmarks/bench_rust.py still runs (tiny iteration counts; the figures are not checked): the Rust crate's
frame decode and failsafe step next to the C library's decode and the Python package's, in one run."""

from __future__ import annotations

import importlib.util
import shutil
import sys

import pytest
from conftest import ROOT


@pytest.mark.skipif(shutil.which("cargo") is None or shutil.which("gcc") is None, reason="cargo or gcc missing")
def test_bench_rust_runs(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_rust", ROOT / "benchmarks" / "bench_rust.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_rust"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main(["--number", "200"])
    finally:
        del sys.modules["bench_rust"]
    expected = {"decode_rust", "decode_ours", "decode_python", "failsafe_step_rust", "failsafe_step_python"}
    assert expected <= set(results)
    assert all(results[k] > 0 for k in expected), results
    assert "Rust/Python" in capsys.readouterr().out
