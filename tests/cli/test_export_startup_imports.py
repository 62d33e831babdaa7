"""What ``battgen export`` of one ULog imports (the list, not the time: benchmarks/bench_export_log.py times it
against pyulog, pandas and ``to_parquet``).

Its fixed cost is its imports: a ULog's export needs numpy, pyarrow's Parquet writer, the IR (to read the bundled
schemas' cached IR) and the generated package, and nothing of the other kinds' readers (python-can, pymavlink's,
YAML's), of the failsafe replay (and, through its parameter checks, the schema loader, jsonschema and pydsdl), or
of pandas, which ``pa.array`` imports (the export builds its arrays from numpy buffers instead)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
from conftest import ROOT

EXAMPLE = ROOT / "docs" / "examples" / "flight.ulg"
NEVER = ("pandas", "jsonschema", "pydsdl", "parsimonious", "can", "yaml", "jinja2", "plotly", "pymavlink", "dronecan")

_RUN = """
import json, sys
from codegen.cli.main import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "modules": sorted(sys.modules)}), file=sys.stderr)
"""


def _export(args: list[str], cache: Path) -> tuple[int, set[str]]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache)}
    done = subprocess.run(
        [sys.executable, "-c", _RUN, "export", *args], capture_output=True, text=True, cwd=ROOT, env=env, timeout=300
    )
    report = json.loads(done.stderr.strip().splitlines()[-1])
    return int(report["code"]), set(report["modules"])


def test_export_of_a_ulog_imports_only_what_a_ulog_needs(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    _export([str(EXAMPLE), "-o", str(tmp_path / "warm"), "-q"], cache)  # the bundled schemas' IR cached
    code, modules = _export([str(EXAMPLE), "-o", str(tmp_path / "ds"), "-q"], cache)
    assert code == 0 and pq.read_table(next((tmp_path / "ds" / "battery").rglob("*.parquet"))).num_rows > 0
    assert sorted(m for m in modules if m.split(".")[0] in NEVER) == []
    assert "pyarrow.compute" not in modules and "numpy.ma" not in modules
    assert sorted(m for m in modules if m.startswith("codegen.frontends.")) == ["codegen.frontends.cache"]
    others = ("codegen.apps.failsafe", "codegen.inputs.can", "codegen.inputs.tlog", "codegen.inputs.documents")
    assert sorted(m for m in modules if m.startswith(others)) == []
    kinds = ("tlog_batches", "can_batches", "dataflash_batches")
    assert sorted(m for m in modules if m.startswith("codegen.apps.battery.") and m.endswith(kinds)) == []
    assert not {"codegen.apps.export.failsafe_tables", "codegen.apps.export.cyphal_raw"} & modules


def test_a_failsafe_export_imports_the_replay(tmp_path: Path) -> None:
    """The replay is imported where a run asks for it (and only then)."""
    code, modules = _export([str(EXAMPLE), "-o", str(tmp_path / "ds"), "-q", "--failsafe", "log"], tmp_path / "c")
    assert code == 0 and "codegen.apps.export.failsafe_tables" in modules
    assert (tmp_path / "ds" / "failsafe").is_dir()
