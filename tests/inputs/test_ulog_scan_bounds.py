"""The compiled walk and gather refuse hostile arguments cleanly (an exception, never a crash).

tests/inputs/ulog_scan_hostile.py makes the calls -- huge and negative offsets, sizes at and past
every limit, integers beyond int64, arguments of the wrong kind or alignment -- in a child process
and checks each outcome against a model of the bounds; here it must finish and say so."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from codegen.inputs.ulog import index as ulog_index

HOSTILE = Path(__file__).with_name("ulog_scan_hostile.py")


def test_hostile_arguments_are_refused_not_crashed_on() -> None:
    if not ulog_index.compiled():
        if os.environ.get("CI") == "true":
            pytest.fail("the C extension codegen/inputs/ulog/_scan.c was not built (CI has gcc)")
        pytest.skip("the C extension is not built")
    run = subprocess.run([sys.executable, str(HOSTILE)], capture_output=True, text=True, timeout=300)
    last = run.stdout.strip().splitlines()[-1:] or [""]
    assert run.returncode == 0, f"exit {run.returncode} at case {last[0]!r}\n{run.stderr[-2000:]}"
    assert last[0].startswith("ok ") and int(last[0].split()[1]) > 30000, last
