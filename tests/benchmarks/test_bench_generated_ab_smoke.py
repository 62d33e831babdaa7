"""benchmarks/bench_generated_ab.py still runs: HEAD's generated/ beside the work tree's, one tiny round
(the figures are not checked; the script itself asserts that both give the same bytes and findings)."""

from __future__ import annotations

import importlib
import shutil
import sys

import pytest
from conftest import ROOT

pytest.importorskip("dronecan")


def test_bench_generated_ab_runs(capsys: pytest.CaptureFixture[str]) -> None:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: no earlier commit to compare with")
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_generated_ab")
    finally:
        sys.path.remove(str(ROOT))
    results = bench.main(["--commit", "HEAD", "--rounds", "1", "--number", "5"])
    assert "dronecan build+encode" in results and "uorb validate (invalid)" in results
    assert all(before > 0 and now > 0 for before, now in results.values())
    assert "now/before" in capsys.readouterr().out
    assert not any(name.startswith(bench.OLD) for name in sys.modules)
