"""``battgen failsafe`` on a JSON Lines stream of battery samples against the script a user would write instead:
``json`` per line and ArduPilot's battery failsafe rules in a loop (issue 30's row: >= 2 M samples/s, >= 4x it).

The stream: ``--samples`` samples (default 1 M) of one battery at 20 Hz, disarmed for its first 100, the voltage
falling from 16.8 V through BATT_LOW_VOLT and BATT_CRT_VOLT with noise (so that the BATT_LOW_TIMER runs restart)
and the consumed charge rising through BATT_LOW_MAH. Each side runs in a fresh process, the sides taking turns over
``--rounds`` rounds: ``battgen failsafe STREAM --params P --vehicle copter --json`` and ``python peer.py STREAM``
(the peer's code is :data:`PEER`). Their events (time, battery, level, cause) are compared and must be the same.
``--before`` adds battgen with the columnar reader turned off (the per-sample replay it replaced) for one round.
Prints CPU seconds min and median, samples/s and the ratio of the medians.

Usage: python benchmarks/bench_failsafe_stream.py [--samples N] [--rounds N] [--before] [--quick]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

try:
    from benchmarks.rounds import child, interleaved, machine
except ImportError:  # run as a script: benchmarks/ is the path's first entry
    from rounds import child, interleaved, machine  # type: ignore[no-redef]

LOW_VOLT, CRT_VOLT, TIMER_S, CAPACITY, LOW_MAH, CRT_MAH = 14.4, 14.0, 10, 5000, 1000, 500
PARAMS = (
    f"BATT_MONITOR,4\nBATT_LOW_VOLT,{LOW_VOLT}\nBATT_CRT_VOLT,{CRT_VOLT}\nBATT_LOW_TIMER,{TIMER_S}\n"
    f"BATT_CAPACITY,{CAPACITY}\nBATT_LOW_MAH,{LOW_MAH}\nBATT_CRT_MAH,{CRT_MAH}\nBATT_FS_LOW_ACT,2\nBATT_FS_CRT_ACT,1\n"
)
# the user's script: ArduPilot's AP_BattMonitor::check_failsafes for one battery, as one would write it
PEER = f"""
import json, sys

LOW_VOLT, CRT_VOLT, TIMER_MS, CAPACITY, LOW_MAH, CRT_MAH = {LOW_VOLT}, {CRT_VOLT}, {TIMER_S * 1000}, {CAPACITY}, \\
    {LOW_MAH}, {CRT_MAH}
level = 0
low_start = crt_start = None
with open(sys.argv[1]) as f:
    for line in f:
        s = json.loads(line)
        if not s["armed"]:
            continue
        b = s["battery"]
        now = round(s["t"] * 1000)
        volts = b["voltage_v"]
        remaining = CAPACITY - b["consumed_mah"]
        found = None
        if volts < CRT_VOLT:
            if crt_start is None:
                crt_start = now
            elif now - crt_start > TIMER_MS:
                found = (2, "voltage")
        else:
            crt_start = None
        if found is None and remaining < CRT_MAH:
            found = (2, "capacity")
        if found is None:
            if volts < LOW_VOLT:
                if low_start is None:
                    low_start = now
                elif now - low_start > TIMER_MS:
                    found = (1, "voltage")
            else:
                low_start = None
        if found is None and remaining < LOW_MAH:
            found = (1, "capacity")
        if found is not None and found[0] > level:
            level = found[0]
            print(s["t"], 1, "LOW" if level == 1 else "CRITICAL", found[1])
"""
BEFORE = (
    "import sys\n"
    "import codegen.apps.failsafe.jsonl_columns as columns\n"
    "columns.read_sample_columns = lambda *args, **kwargs: None\n"
    "from codegen.cli.main import main\n"
    "sys.exit(main(sys.argv[1:]))\n"
)


def write_stream(path: Path, samples: int) -> None:
    """The stream, in a fixed pseudo-random way."""
    rng = np.random.default_rng(30)
    k = np.arange(samples)
    t = (k * 0.05).round(2)
    volts = (16.8 - 3.2 * k / samples + rng.normal(0, 0.08, samples)).round(3)
    amps = (12 + rng.normal(0, 1.5, samples)).round(2)
    used = (4800 * k / samples).round(1)
    armed = k >= 100
    with path.open("w", encoding="utf-8") as f:
        for tk, ak, vk, ik, mk in zip(
            t.tolist(), armed.tolist(), volts.tolist(), amps.tolist(), used.tolist(), strict=True
        ):
            f.write(
                f'{{"t": {tk}, "armed": {"true" if ak else "false"}, "battery": {{"voltage_v": {vk}, '
                f'"current_a": {ik}, "consumed_mah": {mk}}}}}\n'
            )


def _events_of_battgen(out: str) -> list[tuple[Any, ...]]:
    return [(e["t"], e["battery"], e["level"], e["cause"]) for e in map(json.loads, out.splitlines())]


def _events_of_peer(out: str) -> list[tuple[Any, ...]]:
    return [(float(t), int(b), level, cause) for t, b, level, cause in (line.split() for line in out.splitlines())]


def run(samples: int = 1_000_000, rounds: int = 5, before: bool = False) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        stream, params, peer = tmp / "stream.jsonl", tmp / "batt.param", tmp / "peer.py"
        write_stream(stream, samples)
        params.write_text(PARAMS, encoding="utf-8")
        peer.write_text(PEER, encoding="utf-8")
        args = ["failsafe", str(stream), "--params", str(params), "--vehicle", "copter", "--json"]
        sides = {
            "battgen failsafe": lambda: child([sys.executable, "-m", "codegen", *args]),
            "json + rules loop": lambda: child([sys.executable, str(peer), str(stream)]),
        }
        times, outputs = interleaved(sides, rounds)
        ours, theirs = _events_of_battgen(outputs["battgen failsafe"]), _events_of_peer(outputs["json + rules loop"])
        if ours != theirs or not ours:
            raise RuntimeError(f"the events differ: battgen {ours}, the rules loop {theirs}")
        if before:
            old, _ = interleaved({"before": lambda: child([sys.executable, "-c", BEFORE, *args])}, 1)
            if _events_of_battgen(_["before"]) != ours:
                raise RuntimeError("the per-sample replay's events differ")
            times["battgen per-sample (before)"] = old["before"]
    print(f"battgen failsafe, {samples:,} samples of JSON Lines, {rounds} interleaved rounds, fresh processes")
    for name, timing in times.items():
        print(f"  {name:30} {timing.text()}  {samples / timing.median / 1e6:6.2f} M samples/s")
    ratio = times["json + rules loop"].median / times["battgen failsafe"].median
    rate = samples / times["battgen failsafe"].median
    print(f"  same {len(ours)} events; battgen / rules loop: {ratio:.2f}x   target >= 4x and >= 2 M samples/s")
    figures = {"samples_per_s": rate, "ratio": ratio, "events": float(len(ours))}
    if "battgen per-sample (before)" in times:
        figures["before_samples_per_s"] = samples / times["battgen per-sample (before)"].median
    return figures


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--before", action="store_true", help="also the per-sample replay (one round)")
    parser.add_argument("--quick", action="store_true", help="20 000 samples, one round (a smoke run)")
    opts = parser.parse_args(argv)
    if opts.quick:
        opts.samples, opts.rounds = min(opts.samples, 20_000), 1
    print(f"machine: {machine()}")
    return run(opts.samples, opts.rounds, opts.before)


if __name__ == "__main__":
    main()
