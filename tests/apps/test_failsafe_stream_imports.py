"""What ``battgen failsafe`` imports to replay a JSON Lines stream of SI samples (the list, not the time:
benchmarks/bench_failsafe_stream.py times it): numpy for the columns, and none of the schemas' machinery, the flight
logs' readers or the generated messages, which such a stream does not use."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

_RUN = """
import json, sys
from codegen.cli.main import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "modules": sorted(sys.modules)}), file=sys.stderr)
"""
# the IR, the schemas' frontends and caches, the code generator, the generated messages, the logs' readers, the
# validators, the data frames: nothing of them is needed for samples in SI
NOT_NEEDED = (
    "codegen.ir", "codegen.frontends", "codegen.backends", "codegen.apps.schemas", "codegen.apps.battery",
    "codegen.inputs.dataflash", "codegen.inputs.ulog", "codegen.inputs.tlog", "codegen.inputs.can",
    "codegen.apps.failsafe.logs", "codegen.apps.failsafe.px4_log", "generated", "jsonschema", "pandas", "pyarrow",
    "pymavlink", "can", "pydsdl", "jinja2", "yaml", "numpy.ma",
)  # fmt: skip


def test_a_stream_of_si_samples_imports_no_schema_machinery(tmp_path: Path) -> None:
    stream, params = tmp_path / "s.jsonl", tmp_path / "p.param"
    rows = [
        {"t": k * 0.5, "armed": True, "battery": {"voltage_v": 12.0 - k * 0.1, "current_a": 5.0}} for k in range(40)
    ]
    stream.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    params.write_text("BATT_MONITOR,4\nBATT_LOW_VOLT,10.5\nBATT_LOW_TIMER,1\nBATT_FS_LOW_ACT,2\n", encoding="utf-8")
    args = ["failsafe", str(stream), "--params", str(params), "--vehicle", "copter", "--json"]
    done = subprocess.run(
        [sys.executable, "-c", _RUN, *args], capture_output=True, text=True, cwd=ROOT, check=False, timeout=120
    )
    report = json.loads(done.stderr.strip().splitlines()[-1])
    assert report["code"] == 0 and [json.loads(e)["level"] for e in done.stdout.splitlines()] == ["LOW"]
    modules = set(report["modules"])
    assert "numpy" in modules and "codegen.apps.failsafe.columnar" in modules  # replayed over columns
    assert sorted(m for m in modules if m in NOT_NEEDED or m.startswith(tuple(f"{n}." for n in NOT_NEEDED))) == []
