"""benchmarks/bench_tlog.py still runs (a tiny tlog packed by pymavlink; the figures are not checked)."""

from __future__ import annotations

import importlib.util
import struct
import sys
from pathlib import Path

import pytest
from conftest import ROOT


def test_bench_tlog_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    msg = common.MAVLink_sys_status_message(0, 0, 0, 500, 12000, 100, 50, 0, 0, 0, 0, 0, 0)
    path = tmp_path / "tiny.tlog"
    path.write_bytes(b"".join(struct.pack(">Q", 1_700_000_000_000_000 + i) + msg.pack(mav) for i in range(20)))
    spec = importlib.util.spec_from_file_location("bench_tlog", ROOT / "benchmarks" / "bench_tlog.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_tlog"] = module
    try:
        spec.loader.exec_module(module)
        results = module.main([str(path), "--repeat", "1"])
    finally:
        del sys.modules["bench_tlog"]
    assert all(value > 0 for value in results.values())
    assert "20 battery records" in capsys.readouterr().out
