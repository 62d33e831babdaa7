"""Conversion: the generated converters in-process (records per second, best of N runs, each pair under each
policy, without and with a loss report), and ``battgen convert`` as a user runs it against what they would
write instead.

The CLI row: ``battgen convert --from dronecan --to mavlink --policy px4 FILE.jsonl -o OUT`` (a fresh
process) against a script looping over the same file with battgen's own converter (``json.loads``,
``BatteryInfo.from_dict``, ``dronecan_to_mavlink``, ``json.dumps(msg.to_dict())``), the sides taking turns
over the rounds, wall and CPU seconds min and median; both outputs are read back and compared value for value
(NaN as battgen spells it).

The generated mavlink -> uorb px4 converter is timed against the same assignments written by hand (PX4's
mavlink_receiver, float32 where its C computes in float), on the same messages, results compared field by field.

Run: python benchmarks/bench_convert.py [--records N] [--repeat N] [--cli-records N] [--rounds N] [--quick]
"""

from __future__ import annotations

import argparse
import io
import json
import math
import os
import random
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from array import array
from collections.abc import Callable
from pathlib import Path
from typing import Any

from generated.convert import LossReport
from generated.convert.dronecan_mavlink import dronecan_to_mavlink
from generated.convert.dronecan_uorb import dronecan_to_uorb, uorb_to_dronecan
from generated.convert.uorb_mavlink import mavlink_to_uorb, uorb_to_mavlink
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo
from generated.mavlink import BatteryStatus as MavlinkBatteryStatus
from generated.uorb import BatteryStatus as UorbBatteryStatus

_F32 = struct.Struct("<f")


def hand_mavlink_to_uorb_px4(m: MavlinkBatteryStatus) -> UorbBatteryStatus:
    """PX4's mavlink_receiver written by hand: the same assignments, float32 where its C computes in float."""
    pack, unpack = _F32.pack, _F32.unpack
    voltages = m.voltages
    n = 0
    while n < 10 and voltages[n] < 65535:
        n += 1
    cells = array("f", [v / 1000.0 for v in voltages[:n]]).tolist() + [0.0] * (14 - n)
    total = 0.0
    for c in cells[:n]:
        total = unpack(pack(total + c))[0]
    remaining = unpack(pack(m.battery_remaining / 100.0))[0]
    if remaining < 0.05000000074505806:  # the receiver's thresholds, as float32 compares see them
        warning = 3
    elif remaining < 0.07000000029802322:
        warning = 2
    elif remaining < 0.15000000596046448:
        warning = 1
    else:
        warning = 0
    return UorbBatteryStatus(
        connected=True,
        voltage_v=total,
        current_a=unpack(pack(m.current_battery / 100.0))[0],
        current_average_a=0.0,
        discharged_mah=unpack(pack(float(m.current_consumed)))[0],
        remaining=remaining,
        scale=0.0,
        time_remaining_s=0.0,
        temperature=float(m.temperature),
        cell_count=n,
        voltage_cell_v=cells,
        warning=warning,
        remaining_capacity_wh=0.0,
        nominal_voltage=0.0,
    )


def generated_vs_hand(items: list[tuple[Any, ...]], rounds: int) -> dict[str, float]:
    """The generated mavlink -> uorb px4 converter against the hand-written assignments, on the same messages,
    interleaved rounds; the results compared field by field."""
    messages = [args[0] for args in items]
    if [mavlink_to_uorb(m, policy="px4") for m in messages] != [hand_mavlink_to_uorb_px4(m) for m in messages]:
        raise RuntimeError("the generated converter and the hand-written one disagree")
    times: dict[str, list[float]] = {"generated": [], "hand-written": []}
    for _ in range(rounds):
        for name, fn in (
            ("generated", lambda m: mavlink_to_uorb(m, policy="px4")),
            ("hand-written", hand_mavlink_to_uorb_px4),
        ):
            started = time.perf_counter()
            for m in messages:
                fn(m)
            times[name].append(time.perf_counter() - started)
    n = len(messages)
    print(f"mavlink -> uorb px4, {n} messages, {rounds} interleaved rounds, us/record min / median:")
    for name, t in times.items():
        print(f"  {name:<14} {min(t) / n * 1e6:8.2f} / {statistics.median(t) / n * 1e6:8.2f}")
    ratio = statistics.median(times["generated"]) / statistics.median(times["hand-written"])
    print(f"  the generated converter takes {ratio:.2f}x the hand-written assignments (target <= 1.5x); results equal")
    return {"generated x_hand_written": ratio}


def records(n: int) -> tuple[list[tuple[Any, ...]], list[tuple[Any, ...]]]:
    rng = random.Random(5)
    dronecan, uorb = [], []
    for _ in range(n):
        cells = [round(rng.uniform(3.3, 4.2), 3) for _ in range(rng.randint(0, 14))]
        info = BatteryInfo(voltage=sum(cells) or 12.0, current=rng.uniform(0, 60), temperature=rng.uniform(270, 330),
                           state_of_charge_pct=rng.randint(0, 100), battery_id=rng.randint(0, 3),
                           remaining_capacity_wh=math.nan, full_charge_capacity_wh=rng.uniform(50, 100))  # fmt: skip
        dronecan.append((info, BatteryInfoAux(voltage_cell=cells, nominal_voltage=14.8) if cells else None))
        uorb.append((dronecan_to_uorb(*dronecan[-1]),))
    return dronecan, uorb


def rate(fn: Callable[..., Any], items: list[tuple[Any, ...]], repeat: int, **kw: Any) -> float:
    best = math.inf
    for _ in range(repeat):
        started = time.perf_counter()
        for args in items:
            fn(*args, **kw)
        best = min(best, time.perf_counter() - started)
    return len(items) / best


def rate_with_report(fn: Callable[..., Any], items: list[tuple[Any, ...]], repeat: int, **kw: Any) -> float:
    best = math.inf
    for _ in range(repeat):
        started = time.perf_counter()
        for args in items:
            fn(*args, report=LossReport(), **kw)
        best = min(best, time.perf_counter() - started)
    return len(items) / best


def cli_rate(n: int, repeat: int) -> float:
    from codegen.cli.main import main

    line = json.dumps({"voltage": 12.6, "temperature": 298.15, "state_of_charge_pct": 55}) + "\n"
    data = (line * n).encode()
    best = math.inf
    import sys

    for _ in range(repeat):
        stdin, stdout = sys.stdin, sys.stdout
        sys.stdin = io.TextIOWrapper(io.BytesIO(data))
        sys.stdout = io.TextIOWrapper(io.BytesIO())
        try:
            started = time.perf_counter()
            main(["convert", "--from", "dronecan", "--to", "mavlink", "--policy", "px4"])
            best = min(best, time.perf_counter() - started)
        finally:
            sys.stdin, sys.stdout = stdin, stdout
    return n / best


ROOT = Path(__file__).resolve().parent.parent

SCRIPT = """\
import json, sys
from generated.convert.dronecan_mavlink import dronecan_to_mavlink
from generated.dronecan.uavcan.equipment.power import BatteryInfo
with open(sys.argv[1], encoding="utf-8") as f, open(sys.argv[2], "w", encoding="utf-8") as out:
    for line in f:
        msg = dronecan_to_mavlink(BatteryInfo.from_dict(json.loads(line)), policy="px4")
        out.write(json.dumps(msg.to_dict()) + "\\n")
"""


def cli_records(n: int, seed: int = 30) -> list[dict[str, Any]]:
    """DroneCAN BatteryInfo records as a log export has them (remaining_capacity_wh unknown)."""
    rng = random.Random(seed)
    return [
        {
            "voltage": round(rng.uniform(13.0, 16.8), 3),
            "current": round(rng.uniform(0.0, 60.0), 3),
            "temperature": round(rng.uniform(270.0, 330.0), 2),
            "state_of_charge_pct": rng.randint(0, 100),
            "battery_id": rng.randint(0, 3),
            "status_flags": rng.choice((0, 1)),
            "remaining_capacity_wh": "NaN",
            "full_charge_capacity_wh": round(rng.uniform(50.0, 100.0), 2),
        }
        for _ in range(n)
    ]


def _plain(value: Any) -> Any:
    """A value read back from either output, NaN and the infinities spelled as battgen writes them."""
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _run(argv: list[str], env: dict[str, str]) -> tuple[float, float]:
    before, start = os.times(), time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    wall, after = time.perf_counter() - start, os.times()
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
    return wall, (after.children_user - before.children_user) + (after.children_system - before.children_system)


def cli_vs_script(n: int, rounds: int) -> dict[str, float]:
    """``battgen convert`` of a JSON Lines file against a per-record loop over battgen's converter, fresh
    processes, interleaved rounds (a first untimed round writes the bytecode and the caches)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        env["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")
        data = Path(tmp) / "info.jsonl"
        data.write_text("".join(json.dumps(r) + "\n" for r in cli_records(n)), encoding="utf-8")
        script = Path(tmp) / "loop.py"
        script.write_text(SCRIPT, encoding="utf-8")
        outs = {"battgen convert": Path(tmp) / "battgen.jsonl", "script loop": Path(tmp) / "script.jsonl"}
        sides = {
            "battgen convert": [
                *(sys.executable, "-m", "codegen", "convert", "--from", "dronecan", "--to", "mavlink"),
                *("--policy", "px4", str(data), "-o", str(outs["battgen convert"])),
            ],
            "script loop": [sys.executable, str(script), str(data), str(outs["script loop"])],
        }
        wall: dict[str, list[float]] = {name: [] for name in sides}
        cpu: dict[str, list[float]] = {name: [] for name in sides}
        for round_ in range(rounds + 1):
            for name, argv in sides.items():
                w, c = _run(argv, env)
                if round_:
                    wall[name].append(w)
                    cpu[name].append(c)
        read = {name: [_plain(json.loads(t)) for t in path.read_text().splitlines()] for name, path in outs.items()}
        if read["battgen convert"] != read["script loop"] or len(read["script loop"]) != n:
            raise RuntimeError("battgen convert and the script loop wrote different records")
    print(f"CLI, {n} JSON Lines records dronecan -> mavlink px4, fresh processes, {rounds} interleaved rounds (s):")
    print(f"  {'':<18} {'wall min / median':>20} {'cpu min / median':>20}")
    for name in sides:
        print(f"  {name:<18} {min(wall[name]):9.3f} /{statistics.median(wall[name]):9.3f}", end="")
        print(f" {min(cpu[name]):9.3f} /{statistics.median(cpu[name]):9.3f}")
    ratio = statistics.median(cpu["script loop"]) / statistics.median(cpu["battgen convert"])
    wall_ratio = statistics.median(wall["script loop"]) / statistics.median(wall["battgen convert"])
    print(f"  battgen convert is {ratio:.2f}x the script in CPU, {wall_ratio:.2f}x in wall (target >= 1x)")
    print(f"  outputs: {n} records, equal value for value")
    # "cli x_vs_loop" is the figure benchmarks/run_all.py reads for its table; the older name kept beside it
    return {
        "cli convert battgen_s": statistics.median(cpu["battgen convert"]),
        "cli x_vs_loop": ratio,
        "cli convert x_vs_script": ratio,
        "cli x_vs_loop wall": wall_ratio,
    }


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=2000, help="in-process rows")
    parser.add_argument("--repeat", type=int, default=5, help="in-process rows: best of this many")
    parser.add_argument("--cli-records", type=int, default=100_000, help="CLI row: JSON Lines records")
    parser.add_argument("--rounds", type=int, default=5, help="CLI row: interleaved rounds")
    parser.add_argument("--quick", action="store_true", help="10k CLI records, 3 rounds, fewer repeats")
    args = parser.parse_args(argv)
    if args.quick:
        args.cli_records, args.rounds, args.repeat = min(args.cli_records, 10_000), 3, 3
    dronecan, uorb = records(args.records)
    mav = [(uorb_to_mavlink(*u),) for u in uorb]
    results: dict[str, float] = {}
    cases: list[tuple[str, Callable[..., Any], list[tuple[Any, ...]]]] = [
        ("dronecan->uorb", dronecan_to_uorb, dronecan),
        ("uorb->dronecan", uorb_to_dronecan, uorb),
        ("uorb->mavlink", uorb_to_mavlink, uorb),
        ("mavlink->uorb", mavlink_to_uorb, mav),
        ("dronecan->mavlink", dronecan_to_mavlink, dronecan),
    ]
    print(f"{'pair':<20} {'policy':<7} {'records/s':>12} {'with report':>12}")
    for name, fn, items in cases:
        for policy in ("strict", "px4"):
            plain = rate(fn, items, args.repeat, policy=policy)
            reported = rate_with_report(fn, items, args.repeat, policy=policy)
            results[f"{name} {policy}"] = plain
            results[f"{name} {policy} report"] = reported
            print(f"{name:<20} {policy:<7} {plain:12,.0f} {reported:12,.0f}")
    results["cli jsonl dronecan->mavlink px4"] = cli_rate(args.records, max(1, args.repeat // 2))
    print(f"{'CLI JSON Lines':<20} {'px4':<7} {results['cli jsonl dronecan->mavlink px4']:12,.0f}")
    results.update(generated_vs_hand(mav, args.rounds))
    results.update(cli_vs_script(args.cli_records, args.rounds))
    return results


if __name__ == "__main__":
    main()
