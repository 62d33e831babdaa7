"""An output that cannot be written (here a file-size limit, as a full disk behaves: every write past it fails):
one line naming the dataset and the OS error, exit 2, no log counted as unreadable and nothing half-written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.shared_data import REAL_LOGS, require

_RUN = """
import resource, signal, sys
from codegen.apps.battery.catalog import bundled_catalog
from codegen.cli.main import main
bundled_catalog()  # the schemas are read (and their temporary copies written) before the disk "fills"
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit then fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_full_disk_stops_the_run_with_one_line(tmp_path: Path, jobs: str) -> None:
    logs = [require(REAL_LOGS / "sample_px4_events.ulg"), require(REAL_LOGS / "sample_log_small.ulg")]
    out = tmp_path / "ds"
    done = subprocess.run(
        [sys.executable, "-c", _RUN, "export", *map(str, logs), "-o", str(out), "--raw", "--jobs", jobs],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"battgen: {out}") and "cannot write" in lines[0], lines
    assert "File too large" in lines[0] and "unreadable" not in done.stderr
    assert not list(out.rglob("*.parquet")) and not list(out.glob(".tmp-*"))
    assert not (out / "logs").exists() or not list((out / "logs").iterdir())
