"""The PX4 failsafe replay of real ULogs against pyulog reading the same topics (the peer: what a user of pyulog
would read before replaying anything).

Ours: :func:`codegen.apps.failsafe.px4_log.read_px4_log` (the battery view plus commander's topics) and
:func:`~codegen.apps.failsafe.px4_replay.replay_px4` (levels, commander, actions, the checks against the log). The
peer: ``pyulog.ULog`` with battery_status, failsafe_flags, vehicle_status and rtl_time_estimate. Best of
``--repeat`` runs each; prints the seconds and the ratio.

Usage: python benchmarks/bench_px4_failsafe.py [--repeat N] [LOG ...]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
LOGS = (
    "corpus/realworld3/ulog/fsyrh_log_61_2024-2-6-16-27-02.ulg",
    "corpus/realworld3/ulog/auterion_quadrotor_local.ulg",
    "data/ulog/sample_px4_events.ulg",
)
TOPICS = ["battery_status", "failsafe_flags", "vehicle_status", "rtl_time_estimate"]


def bench(log: Path, repeat: int) -> dict[str, float]:
    from pyulog import ULog

    from codegen.apps.failsafe.px4_log import read_px4_log
    from codegen.apps.failsafe.px4_replay import replay_px4

    ours, replay, peer = float("inf"), float("inf"), float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        read = read_px4_log(log)
        middle = time.perf_counter()
        replay_px4(read)
        end = time.perf_counter()
        ULog(str(log), TOPICS)
        peer_end = time.perf_counter()
        ours, replay, peer = min(ours, end - start), min(replay, end - middle), min(peer, peer_end - end)
    print(
        f"{log.name}: ours (read + replay) {ours * 1e3:7.1f} ms (replay alone {replay * 1e3:5.1f} ms) | "
        f"pyulog read {peer * 1e3:7.1f} ms | ours / pyulog {ours / peer:.2f}x"
    )
    return {"ours": ours, "replay": replay, "pyulog": peer}


def run(logs: list[Path], repeat: int = 5) -> dict[str, dict[str, float]]:
    return {log.name: bench(log, repeat) for log in logs}


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("logs", nargs="*", type=Path)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeat = 1
    logs = args.logs or [SHARED / name for name in LOGS if (SHARED / name).is_file()]
    if not logs:
        raise SystemExit(f"no logs: give some, or put ../shared beside the repository ({SHARED})")
    return run(logs[-1:] if args.quick else logs, args.repeat)


if __name__ == "__main__":
    main()
