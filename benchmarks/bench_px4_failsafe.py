"""``battgen failsafe LOG.ulg`` (PX4's battery failsafe replayed from the log) against the script a pyulog user would
write instead: pyulog reading battery_status and vehicle_status, and PX4's warning rules in a loop.

Each side runs in a fresh process on the same real ULogs, the sides taking turns over ``--rounds`` rounds:
``battgen failsafe LOG --json`` and ``python peer.py LOG`` (the peer's code is :data:`PEER`: ``Battery::
determineWarning`` on ``battery_status.remaining`` with the log's BAT_*_THR as float32, a battery's warning
recomputed while it is connected and initialised, commander's warning the worst of them and only rising while
``vehicle_status`` says armed, an event where it rises while armed or is above NONE at arming). The events (time
since the log's start, battery, level) are compared and must be the same; battgen also checks its replay against
what the firmware logged and chooses commander's action, which the peer leaves out. Prints CPU seconds min and
median per side and the ratio of the medians (the peer's over battgen's: above 1, battgen is faster).

Usage: python benchmarks/bench_px4_failsafe.py [--rounds N] [--quick] [LOG ...]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

try:
    from benchmarks.rounds import child, interleaved, machine
except ImportError:  # run as a script: benchmarks/ is the path's first entry
    from rounds import child, interleaved, machine  # type: ignore[no-redef]

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
LOGS = (
    "corpus/realworld3/ulog/fsyrh_log_61_2024-2-6-16-27-02.ulg",
    "corpus/realworld3/ulog/auterion_quadrotor_local.ulg",
    "data/ulog/sample_px4_events.ulg",
)
LEVELS = ("NONE", "LOW", "CRITICAL", "EMERGENCY")
# the user's script: PX4's battery warning and commander's rising-only failsafe warning, as one would write them
PEER = f"""
import sys
import numpy as np
from pyulog import ULog

LEVELS = {LEVELS!r}
u = ULog(sys.argv[1], ["battery_status", "vehicle_status"])
p = u.initial_parameters
low, crit, emer = (np.float32(p.get(n, d)) for n, d in (("BAT_LOW_THR", 0.15), ("BAT_CRIT_THR", 0.07),
                                                          ("BAT_EMERGEN_THR", 0.05)))
status = next(d for d in u.data_list if d.name == "vehicle_status")
arm_t, arm_v = status.data["timestamp"], status.data["arming_state"] == 2  # ARMING_STATE_ARMED
updates = []
for d in u.data_list:
    if d.name != "battery_status":
        continue
    warning, since = 0, 0.0
    for t, s, c in zip(d.data["timestamp"].tolist(), d.data["remaining"].astype(np.float32).tolist(),
                       d.data["connected"].tolist()):
        s = np.float32(s)
        if not c:
            since = t / 1e6
        if c and t / 1e6 > since + 2.0:  # connected and initialised for 2 s
            warning = 3 if s < emer else 2 if s < crit else 1 if s < low else 0
        updates.append((t, d.multi_id + 1, warning if c else None))
updates.sort()
latest, flag, previous, was_armed = {{}}, 0, 0, False
for t, battery, warning in updates:
    latest[battery] = warning
    k = np.searchsorted(arm_t, t, side="right") - 1
    armed = bool(k >= 0 and arm_v[k])
    worst = max((w for w in latest.values() if w is not None), default=0)
    flag = max(flag, worst) if armed else worst
    if armed and flag > 0 and (flag > previous or not was_armed):
        print(f"{{(t - u.start_timestamp) / 1e6:.6f}}", battery, LEVELS[flag])
    previous, was_armed = flag, armed
"""


def _events_of_battgen(out: str) -> list[tuple[str, int, str]]:
    """battgen's state-of-charge events (the remaining-flight-time ones are not the peer's business)."""
    events = [json.loads(line) for line in out.splitlines()]
    return [(f"{e['t']:.6f}", e["battery"], e["level"]) for e in events if e["cause"] == "charge"]


def _events_of_peer(out: str) -> list[tuple[str, int, str]]:
    return [(t, int(b), level) for t, b, level in (line.split() for line in out.splitlines())]


def bench(log: Path, peer: Path, rounds: int) -> dict[str, float]:
    sides = {
        "battgen failsafe": lambda: child([sys.executable, "-m", "codegen", "failsafe", str(log), "--json"]),
        "pyulog + rules loop": lambda: child([sys.executable, str(peer), str(log)]),
    }
    times, outputs = interleaved(sides, rounds)
    ours, theirs = _events_of_battgen(outputs["battgen failsafe"]), _events_of_peer(outputs["pyulog + rules loop"])
    if ours != theirs:
        raise RuntimeError(f"{log.name}: the events differ: battgen {ours}, the rules loop {theirs}")
    print(f"{log.name}: {len(ours)} events, the same on both sides")
    for name, timing in times.items():
        print(f"  {name:22} {timing.text()}")
    ratio = times["pyulog + rules loop"].median / times["battgen failsafe"].median
    print(f"  pyulog loop / battgen: {ratio:.2f}x")
    return {
        "ours": times["battgen failsafe"].median,
        "peer": times["pyulog + rules loop"].median,
        "ratio": ratio,
        "events": float(len(ours)),
    }


def run(logs: list[Path], rounds: int = 5) -> dict[str, dict[str, float]]:
    with tempfile.TemporaryDirectory() as tmp:
        peer = Path(tmp) / "peer.py"
        peer.write_text(PEER, encoding="utf-8")
        print(f"battgen failsafe on PX4 ULogs, {rounds} interleaved rounds, fresh processes, CPU seconds")
        return {log.name: bench(log, peer, rounds) for log in logs}


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("logs", nargs="*", type=Path)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="one log, one round (a smoke run)")
    args = parser.parse_args(argv)
    logs = args.logs or [SHARED / name for name in LOGS if (SHARED / name).is_file()]
    if not logs:
        raise SystemExit(f"no logs: give some, or put ../shared beside the repository ({SHARED})")
    print(f"machine: {machine()}")
    return run(logs[-1:] if args.quick else logs, 1 if args.quick else args.rounds)


if __name__ == "__main__":
    main()
