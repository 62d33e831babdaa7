"""Conversion throughput of the generated converters (records per second, best of N runs).

Run: python benchmarks/bench_convert.py [--records N] [--repeat N]
Each pair converts the same N varied records, under each policy, without and with a loss
report; the CLI path (JSON Lines in and out) is measured too.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import random
import time
from collections.abc import Callable
from typing import Any

from generated.convert import LossReport
from generated.convert.dronecan_mavlink import dronecan_to_mavlink
from generated.convert.dronecan_uorb import dronecan_to_uorb, uorb_to_dronecan
from generated.convert.uorb_mavlink import mavlink_to_uorb, uorb_to_mavlink
from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
from generated.dronecan.uavcan.equipment.power import BatteryInfo


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


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser()
    parser.add_argument("--records", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
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
    return results


if __name__ == "__main__":
    main()
