"""The start-up benchmark still runs: battgen and the peers' scripts on the shared logs (figures not checked;
the benchmark itself checks that battgen and mavlogdump find the same BATTERY_STATUS records in the tlog)."""

from __future__ import annotations

import importlib
import sys

import pytest
from conftest import ROOT

ULOG = ROOT.parent / "shared" / "data" / "ulog" / "sample_log_small.ulg"
TLOG = ROOT.parent / "shared" / "corpus" / "realworld3" / "tlog" / "wlichon_baseline_20260406_010254.tlog"


@pytest.mark.skipif(not (ULOG.is_file() and TLOG.is_file()), reason="needs the shared ULog and tlog")
def test_bench_startup_runs(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT))
    try:
        bench = importlib.import_module("benchmarks.bench_startup")
    finally:
        sys.path.remove(str(ROOT))
    figures = bench.run(ULOG, TLOG, rounds=1)
    assert figures["help: battgen / ulog_info battgen_s"] > 0
    assert figures["tlog validate / mavlogdump peer_s"] > 0
    out = capsys.readouterr().out
    assert "one record, IR cache cold" in out and "ratio" in out
