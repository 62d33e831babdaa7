"""``battgen export`` of one real PX4 log against the script a user would write instead: pyulog, pandas and
``to_parquet`` (issue 30's row: at least as fast).

Both run in fresh processes on ``../shared/data/ulog/sample_px4_events.ulg`` (157 battery_status records), the sides
taking turns over ``--rounds`` rounds; CPU seconds min and median and the ratio of the medians. The outputs are
read back and compared value for value: battgen's ``pack_voltage``, ``current`` and ``state_of_charge`` against the
script's ``voltage_v``, ``current_a`` (-1, uORB's unknown, as empty) and ``remaining`` (as float32, the log's
own type).

Usage: python benchmarks/bench_export_log.py [--rounds N] [--quick] [LOG]
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

try:
    from benchmarks.rounds import child, interleaved, machine
except ImportError:  # run as a script: benchmarks/ is the path's first entry
    from rounds import child, interleaved, machine  # type: ignore[no-redef]

LOG = Path(__file__).resolve().parents[2] / "shared" / "data" / "ulog" / "sample_px4_events.ulg"
PEER = """
import sys
import pandas as pd
from pyulog import ULog

ulog = ULog(sys.argv[1], message_name_filter_list=["battery_status"])
for d in ulog.data_list:
    pd.DataFrame(d.data).to_parquet(f"{sys.argv[2]}/battery_status_{d.multi_id}.parquet")
"""


def _values_of_battgen(out: Path) -> np.ndarray:
    import pyarrow.parquet as pq

    table = pq.read_table(next((out / "battery").rglob("*.parquet"))).to_pandas().sort_values("t")
    return table[["pack_voltage", "current", "state_of_charge"]].to_numpy(np.float64).astype(np.float32)


def _values_of_peer(out: Path) -> np.ndarray:
    import pandas as pd

    frame = pd.concat(pd.read_parquet(p) for p in sorted(out.glob("*.parquet"))).sort_values("timestamp")
    values = np.array(frame[["voltage_v", "current_a", "remaining"]].to_numpy(np.float64))
    values[values[:, 1] == -1, 1] = np.nan  # uORB's "unknown" current, which battgen's export leaves empty
    return values.astype(np.float32)


def run(log: Path = LOG, rounds: int = 5) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        ours_out, peer_out, peer = tmp / "battgen", tmp / "peer", tmp / "peer.py"
        peer.write_text(PEER, encoding="utf-8")

        def battgen() -> tuple[float, float, str]:
            shutil.rmtree(ours_out, ignore_errors=True)
            return child([sys.executable, "-m", "codegen", "export", str(log), "-o", str(ours_out), "-q"])

        def script() -> tuple[float, float, str]:
            shutil.rmtree(peer_out, ignore_errors=True)
            peer_out.mkdir()
            return child([sys.executable, str(peer), str(log), str(peer_out)])

        times, _ = interleaved({"battgen export": battgen, "pyulog + pandas + to_parquet": script}, rounds)
        ours, theirs = _values_of_battgen(ours_out), _values_of_peer(peer_out)
        same = ours.shape == theirs.shape and np.array_equal(ours, theirs, equal_nan=True)
        if not same:
            raise RuntimeError(f"the exported values differ: battgen {ours.shape}, the script {theirs.shape}")
    print(f"export of {log.name} ({len(ours)} records), {rounds} interleaved rounds, fresh processes")
    for name, timing in times.items():
        print(f"  {name:30} {timing.text()}")
    ratio = times["pyulog + pandas + to_parquet"].median / times["battgen export"].median
    print(f"  same {len(ours)} records' voltage, current and charge; battgen / script: {ratio:.2f}x   target >= 1x")
    return {"ratio": ratio, "battgen_s": times["battgen export"].median}


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("log", nargs="?", type=Path, default=LOG)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="one round (a smoke run)")
    opts = parser.parse_args(argv)
    print(f"machine: {machine()}")
    return run(opts.log, 1 if opts.quick else opts.rounds)


if __name__ == "__main__":
    main()
