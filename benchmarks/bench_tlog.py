"""A tlog's batteries: our one walk (codegen.apps.battery.tlog_batches, through the battery view) against
pymavlink's log reader (``mavutil.mavmmaplog``) reading the same file's BATTERY_STATUS, SYS_STATUS and HEARTBEAT
messages, in one run.

Run: python benchmarks/bench_tlog.py [TLOG] (default: the largest real tlog under ../shared/corpus)
Prints seconds for each (best of ``--repeat``), frames per second and the ratio pymavlink / ours.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from codegen.apps.battery.view import read_view

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
WANTED = ["BATTERY_STATUS", "SYS_STATUS", "HEARTBEAT"]


def default_tlog() -> Path:
    found = sorted((SHARED / "corpus").rglob("*.tlog"), key=lambda p: p.stat().st_size)
    if not found:
        raise SystemExit(f"no .tlog under {SHARED / 'corpus'}: give one")
    return found[-1]


def ours(path: Path) -> int:
    return sum(chunk.n for chunk in read_view(path))


def pymavlink(path: Path) -> int:
    os.environ["MAVLINK20"] = "1"
    from pymavlink import mavutil

    mavutil.set_dialect("ardupilotmega")
    conn = mavutil.mavmmaplog(str(path))
    n = 0
    while conn.recv_match(type=WANTED) is not None:
        n += 1
    conn.close()
    return n


def best(fn: object, path: Path, repeat: int) -> tuple[float, int]:
    times, got = [], 0
    for _ in range(repeat):
        start = time.perf_counter()
        got = fn(path)  # type: ignore[operator]
        times.append(time.perf_counter() - start)
    return min(times), got


def main(argv: list[str] | None = None) -> dict[str, float]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tlog", nargs="?", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one run each (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeat = 1
    path = args.tlog or default_tlog()
    t_ours, records = best(ours, path, args.repeat)
    t_theirs, messages = best(pymavlink, path, args.repeat)
    size = path.stat().st_size
    print(f"{path.name}: {size / 1e6:.2f} MB, {records} battery records (pymavlink: {messages} messages read)")
    print(f"ours      {t_ours:8.3f} s  {size / t_ours / 1e6:7.1f} MB/s")
    print(f"pymavlink {t_theirs:8.3f} s  {size / t_theirs / 1e6:7.1f} MB/s")
    print(f"ratio pymavlink / ours: {t_theirs / t_ours:.2f}x")
    return {"ours_s": t_ours, "pymavlink_s": t_theirs, "ratio": t_theirs / t_ours}


if __name__ == "__main__":
    main()
