"""``battgen export`` of a million tlog frames within issue 32's budget: under 400 MB resident at its peak, and
allocating no more than a bounded address space (``RLIMIT_AS``) beyond what it imports.

The export runs in a child process of its own, whose address space is capped at its imports' (measured in the
child, as tests/inputs/test_reader_memory.py does), plus the tlog's size (the reader maps the file), plus
:data:`HEADROOM`; an export that held the log's frames (1.6 GB once) fails there with MemoryError. The headroom
is address space, not memory: Arrow's and the C library's per-thread arenas reserve some 300 MB of it while the
Parquet files are written, touching little. The budget itself is the child's resident peak (``VmHWM``): the
memory the issue budgets, whatever address space the allocators reserve. benchmarks/bench_export_memory.py
prints the same peak for each input kind and length.
"""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
from conftest import ROOT

FRAMES = 1_000_000
BUDGET_MB = 400  # issue 32: the export's resident peak at a million tlog frames
HEADROOM = 400 << 20  # address space the export may take beyond its imports and the mapped log

_CHILD = """
import resource, sys
from pathlib import Path
import numpy, pyarrow, pyarrow.parquet
from codegen.apps.battery import tlog_batches
from codegen.apps.export import engine
from codegen.cli import export
from codegen.cli.main import main

def status(key):
    with open("/proc/self/status") as f:
        return int(next(line.split()[1] for line in f if line.startswith(key))) * 1024

headroom, path, out = int(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
cap = status("VmSize:") + path.stat().st_size + headroom
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
try:
    code = main(["export", str(path), "-o", out, "-q"])
except MemoryError:
    print("MemoryError")
    sys.exit(3)
print("exit", code, "peak", status("VmHWM:") >> 20)
"""


def _tlog(path: Path, n: int) -> int:
    """``n`` BATTERY_STATUS frames of one battery at 10 Hz and a vehicle heartbeat a second (arming halfway);
    returns the number of battery frames."""
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    frames = [
        mav.battery_status_encode(0, 0, 0, 2500, [12000 - k] + [65535] * 9, 500, k, -1, 80).pack(mav) for k in range(50)
    ]
    beats = [mav.heartbeat_encode(2, 3, mode, 0, 4).pack(mav) for mode in (1, 129)]
    epoch = 1_700_000_000_000_000
    with path.open("wb") as f:
        for i in range(n):
            stamp = struct.pack(">Q", epoch + i * 100_000)
            if i % 10 == 0:
                f.write(stamp + beats[i >= n // 2])
            f.write(stamp + frames[i % 50])
    return n


def test_a_million_tlog_frames_export_within_the_budget(tmp_path: Path) -> None:
    log = tmp_path / "long.tlog"
    n = _tlog(log, FRAMES)
    out = tmp_path / "ds"
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, str(HEADROOM), str(log), str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=1200,
    )
    assert done.returncode == 0, (done.stdout[-500:], done.stderr[-2000:])
    words = done.stdout.split()
    assert words[:2] == ["exit", "0"], done.stdout
    peak = int(words[words.index("peak") + 1])
    assert peak < BUDGET_MB, f"peak {peak} MB"
    table = pq.read_table(next((out / "battery").rglob("*.parquet")), columns=["t", "armed"])
    assert table.num_rows == n
    armed = table.column("armed").to_pylist()
    assert armed[0] is False and armed[-1] is True  # the heartbeats' arming, as of each record
