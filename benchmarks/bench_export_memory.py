"""Peak memory of ``battgen export`` by input kind and length: a log's memory should be flat in its length.

Each input is made here (a tlog of BATTERY_STATUS frames with 1 Hz heartbeats, a JSON Lines file of uORB records,
a candump capture of DroneCAN BatteryInfo transfers), at two lengths, and exported by the CLI in a fresh process
whose peak resident size is read from the kernel (``ru_maxrss`` of that process alone). The figures printed are
the peaks and their growth from the short to the long input; the issue's budget is 400 MB at a million tlog
frames or JSON Lines records and ten million CAN frames.

    python benchmarks/bench_export_memory.py                 # 100k and 1M tlog/JSONL records, 10M CAN frames
    python benchmarks/bench_export_memory.py --can-long 1000000 --kinds can   # a quicker CAN run
"""

from __future__ import annotations

import argparse
import json
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BUDGET_MB = 400  # issue 32: export's peak at a million tlog frames or JSONL records, ten million CAN frames
_PEAK = """
import resource, subprocess, sys
done = subprocess.run(sys.argv[1:], capture_output=True)
sys.stdout.write(f"{done.returncode} {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss}\\n")
"""


def tlog(path: Path, n: int) -> Path:
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    frames = [
        mav.battery_status_encode(0, 0, 0, 2500, [12000 - k] + [65535] * 9, 500, k, -1, 80).pack(mav) for k in range(50)
    ]
    beat = mav.heartbeat_encode(10, 3, 128, 0, 4).pack(mav)
    epoch = 1_700_000_000_000_000
    with path.open("wb") as f:
        for i in range(n):
            stamp = struct.pack(">Q", epoch + i * 100_000)
            if i % 10 == 0:
                f.write(stamp + beat)
            f.write(stamp + frames[i % len(frames)])
    return path


def jsonl(path: Path, n: int) -> Path:
    with path.open("w", encoding="utf-8") as f:
        for i in range(n):
            f.write(json.dumps({"timestamp": 1000 * (i + 1), "voltage_v": 16.0 - i * 1e-6, "current_a": 5.0}) + "\n")
    return path


def candump(path: Path, n: int) -> Path:
    """BatteryInfo (a 3-frame transfer) from node 20, ``n`` frames in all."""
    import dronecan
    from dronecan import transport

    msg = dronecan.uavcan.equipment.power.BatteryInfo(voltage=16.0, current=5.0, state_of_charge_pct=80)
    lines: list[list[str]] = []
    for tid in range(32):
        t = transport.Transfer(payload=msg, source_node_id=20, transfer_id=tid, transfer_priority=30)
        lines.append([f"{f.message_id:08X}#{bytes(f.bytes).hex().upper()}" for f in t.to_frames()])
    with path.open("w", encoding="ascii") as f:
        written, k = 0, 0
        while written < n:
            for frame in lines[k % 32]:
                f.write(f"({1_700_000_000 + written * 0.001:.6f}) can0 {frame}\n")
                written += 1
            k += 1
    return path


def peak(args: list[str]) -> tuple[int, float, float]:
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _PEAK, *args], capture_output=True, text=True, check=True).stdout
    code, kib = out.split()
    return int(code), int(kib) / 1024, time.perf_counter() - start


def main(argv: list[str] | None = None) -> dict[str, list[float]]:
    """The peaks (MB) by kind, short then long."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--short", type=int, default=100_000)
    parser.add_argument("--long", type=int, default=1_000_000)
    parser.add_argument("--can-long", type=int, default=10_000_000, help="the issue's budget: 10M frames")
    parser.add_argument("--kinds", default="tlog,jsonl,can", help="comma-separated: tlog, jsonl, can")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.short, args.long, args.can_long, args.kinds = 200, 400, 400, "jsonl"
    results: dict[str, list[float]] = {}
    makers = {
        "tlog": (tlog, ".tlog", args.long),
        "jsonl": (jsonl, ".jsonl", args.long),
        "can": (candump, ".log", args.can_long),
    }
    print(f"{'kind':6s} {'records':>10s} {'peak MB':>9s} {'seconds':>8s}  exit")
    with tempfile.TemporaryDirectory() as folder:
        for kind, (make, suffix, long) in makers.items():
            if kind not in args.kinds.split(","):
                continue
            peaks = []
            for n in (args.short, long):
                path = make(Path(folder) / f"{kind}-{n}{suffix}", n)
                command = [
                    sys.executable,
                    "-m",
                    "codegen",
                    "export",
                    str(path),
                    "-o",
                    str(Path(folder) / f"ds-{kind}-{n}"),
                    "-q",
                ]
                if kind == "jsonl":
                    command += ["--message", "uorb.BatteryStatus"]
                code, mb, seconds = peak(command)
                peaks.append(mb)
                print(f"{kind:6s} {n:10d} {mb:9.1f} {seconds:8.1f}  {code}")
                path.unlink()
            print(f"{kind:6s} growth from {args.short} to {long}: {peaks[1] - peaks[0]:+.1f} MB")
            verdict = "within" if peaks[1] < BUDGET_MB else "OVER"
            print(f"{kind:6s} peak at {long} records: {peaks[1]:.1f} MB, {verdict} the {BUDGET_MB} MB budget")
            results[kind] = peaks
    return results


if __name__ == "__main__":
    main()
