"""The DataFlash benchmark still runs (the text excerpt of the corpus; the figures are not checked)."""

from __future__ import annotations

import importlib
import os
import sys

import pytest
from conftest import ROOT

pytest.importorskip("pymavlink")


def test_bench_dataflash_runs(capsys: pytest.CaptureFixture[str]) -> None:
    log = ROOT.parent / "shared" / "corpus" / "realworld3" / "dataflash" / "robert_lefebvre_octo_PM.excerpt.log"
    if not log.is_file():
        if os.environ.get("CI"):
            pytest.fail(f"missing {log}")
        pytest.skip(f"missing {log}")
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_dataflash")
    finally:
        sys.path.remove(str(ROOT))
    figures = bench.run(log)
    assert figures["records"] == figures["ref_records"] > 0
    assert "records/s" in capsys.readouterr().out
