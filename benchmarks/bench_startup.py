"""Start-up: battgen as a user runs it against the log tools they would run instead, fresh processes.

Each row runs battgen's command and the peer's script on the same input, each in a fresh interpreter,
the sides taking turns over the rounds (the first, untimed, writes the bytecode and the bundled
schemas' IR cache, as a user's first run does); wall and CPU seconds, min and median, and the ratio
peer / battgen of the medians (above 1: battgen is faster):

* ``battgen --help`` against ``ulog_info --help`` (pyulog) and ``mavlogdump.py --help`` (pymavlink);
* ``battgen validate`` of one JSON Lines record against ``ulog_info`` on the small ULog (the least a
  log tool does);
* ``battgen validate`` of a ULog against ``ulog_info`` on it;
* ``battgen validate --message mavlink.BATTERY_STATUS`` of a tlog against
  ``mavlogdump.py --types BATTERY_STATUS`` on it (the outputs' record counts compared);
* ``battgen validate`` of one record with the IR cache empty (each round clears it): what the first
  run after an install or a schema change pays.

The children run with bytecode writing on (this machine's environment may set PYTHONDONTWRITEBYTECODE,
which would make every battgen run compile its sources while the peers' installed .pyc are read).

Usage: python benchmarks/bench_startup.py [--rounds N] [ULOG] [TLOG]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
DEFAULT_ULOG = SHARED / "data" / "ulog" / "sample_log_small.ulg"
DEFAULT_TLOG = SHARED / "corpus" / "realworld3" / "tlog" / "wlichon_baseline_20260406_010254.tlog"
BIN = Path(sys.executable).parent
RECORD = '{"voltage_v": 16.4, "remaining": 0.5, "max_error": 1}\n'


@dataclass
class Timing:
    wall: list[float]
    cpu: list[float]

    def median(self) -> float:
        return statistics.median(self.wall)


def _script(name: str) -> list[str]:
    found = BIN / name
    return [sys.executable, str(found)] if found.is_file() else [name]


def _battgen(*args: str) -> list[str]:
    return [sys.executable, "-m", "codegen", *args]


def _run(argv: list[str], env: dict[str, str]) -> tuple[float, float, str]:
    before, start = os.times(), time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    wall, after = time.perf_counter() - start, os.times()
    if done.returncode not in (0, 1):  # 1: a validation finding, still a run
        raise RuntimeError(f"{' '.join(argv)}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, cpu, done.stdout + done.stderr


def run(ulog: Path = DEFAULT_ULOG, tlog: Path = DEFAULT_TLOG, rounds: int = 7) -> dict[str, float]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        record = Path(tmp) / "one.jsonl"
        record.write_text(RECORD, encoding="utf-8")
        cache = Path(tmp) / "cache"
        env["XDG_CACHE_HOME"] = str(cache)
        rows: dict[str, tuple[list[str], list[str]]] = {
            "help: battgen / ulog_info": (_battgen("--help"), [*_script("ulog_info"), "--help"]),
            "help: battgen / mavlogdump": (_battgen("--help"), [*_script("mavlogdump.py"), "--help"]),
            "one record / ulog_info": (
                _battgen("validate", "--message", "uorb.BatteryStatus", str(record)),
                [*_script("ulog_info"), str(ulog)],
            ),
            "ulog validate / ulog_info": (_battgen("validate", str(ulog)), [*_script("ulog_info"), str(ulog)]),
            "tlog validate / mavlogdump": (
                _battgen("validate", "--message", "mavlink.BATTERY_STATUS", str(tlog)),
                [*_script("mavlogdump.py"), "--types", "BATTERY_STATUS", str(tlog)],
            ),
        }
        cold = _battgen("validate", "--message", "uorb.BatteryStatus", str(record))
        times: dict[tuple[str, int], Timing] = {}
        outputs: dict[tuple[str, int], str] = {}
        for round_ in range(rounds + 1):
            for name, sides in rows.items():
                for side, argv in enumerate(sides):
                    wall, cpu, out = _run(argv, env)
                    outputs[name, side] = out
                    if round_:  # the first round writes the bytecode and the IR cache
                        t = times.setdefault((name, side), Timing([], []))
                        t.wall.append(wall)
                        t.cpu.append(cpu)
            if round_:
                shutil.rmtree(cache, ignore_errors=True)
                wall, cpu, _ = _run(cold, env)
                t = times.setdefault(("one record, IR cache cold", 0), Timing([], []))
                t.wall.append(wall)
                t.cpu.append(cpu)
    # the same records on both sides of the tlog row: battgen's count, mavlogdump's lines
    battgen_tlog, peer_tlog = outputs["tlog validate / mavlogdump", 0], outputs["tlog validate / mavlogdump", 1]
    dumped = sum(1 for text_line in peer_tlog.splitlines() if "BATTERY_STATUS" in text_line)
    if f"{dumped} record" not in battgen_tlog:
        raise RuntimeError(f"tlog: mavlogdump printed {dumped} BATTERY_STATUS, battgen said: {battgen_tlog[-200:]}")
    figures: dict[str, float] = {}
    print(f"start-up, fresh processes, {rounds} interleaved rounds ({ulog.name}, {tlog.name}, {os.cpu_count()} CPUs)")
    print(f"{'':30}{'battgen wall min/med':>22}{'cpu med':>9}{'peer wall min/med':>20}{'cpu med':>9}{'ratio':>7}")
    for name in [*rows, "one record, IR cache cold"]:
        ours = times[name, 0]
        figures[f"{name} battgen_s"] = ours.median()
        text = f"{name:30}{min(ours.wall):10.3f}s /{ours.median():7.3f}s{statistics.median(ours.cpu):8.3f}s"
        if (name, 1) in times:
            peer = times[name, 1]
            figures[f"{name} peer_s"] = peer.median()
            text += f"{min(peer.wall):8.3f}s /{peer.median():7.3f}s{statistics.median(peer.cpu):8.3f}s"
            text += f"{peer.median() / ours.median():6.2f}x"
        print(text)
    return figures


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("ulog", nargs="?", type=Path, default=DEFAULT_ULOG)
    parser.add_argument("tlog", nargs="?", type=Path, default=DEFAULT_TLOG)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="one round (a smoke run)")
    options = parser.parse_args(argv)
    return run(options.ulog, options.tlog, 1 if options.quick else options.rounds)


if __name__ == "__main__":
    main()
