"""``battgen export`` of a ULog whose battery_status is an older layout, against the hand path.

Run: python benchmarks/bench_ulog_layouts.py [--records N] [--log PATH]
The log is a real older-layout log (default ../shared/data/ulog/sample_px4_events.ulg, PX4 1.14's
battery_status, 167 bytes) with its battery records repeated to --records records (built in a temp
dir, never kept). Timed once each, in one run: ``battgen export`` (parse, columns, the IR's mapping,
Parquet) against what a user writes by hand (pyulog -> pandas -> ``to_parquet``); printed as records/s
of wall time and of the process's CPU time (every thread: records/s/core), and the ratios.
Targets (issue 22): >= 1 M records/s/core and >= 3x the hand path.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_LOG = ROOT.parent / "shared" / "data" / "ulog" / "sample_px4_events.ulg"
TOPIC = "battery_status"


def repeated_log(source: Path, out: Path, records: int) -> int:
    """``source`` with copies of its battery_status data records appended until it holds ``records``."""
    from codegen.inputs.ulog.columns import UlogColumns
    from generated.uorb import BatteryStatus

    data = source.read_bytes()
    with UlogColumns(source, source.name, BatteryStatus) as log:
        offsets = [int(o) for key, offs in log.offsets.items() if key[0] == TOPIC for o in offs]
    # a data record: uint16 size, 'D', uint16 msg_id, payload; its payload starts 5 bytes in
    chunks = [data[o - 5 : o - 2 + int.from_bytes(data[o - 5 : o - 3], "little")] for o in sorted(offsets)]
    block = b"".join(chunks)
    have = len(offsets)
    copies = max(0, -(-(records - have) // have))
    out.write_bytes(data + block * copies)
    return have * (copies + 1)


def battgen_export(path: Path, out: Path) -> None:
    from codegen.cli.main import main as cli

    code = cli(["export", str(path), "-o", str(out), "-q"])
    assert code == 0, code


def hand_path(path: Path, out: Path) -> int:
    import pandas as pd
    from pyulog import ULog

    ulog = ULog(str(path), message_name_filter_list=[TOPIC])
    frames = [pd.DataFrame(d.data).assign(multi_id=d.multi_id) for d in ulog.data_list]
    frame = pd.concat(frames)
    frame.to_parquet(out / "battery.parquet")
    return len(frame)


def run(log: Path, records: int) -> dict[str, float]:
    r: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "repeated.ulg"
        n = repeated_log(log, path, records)
        r["records"] = n
        # the first run of each pays its imports (a user's one command); the second is the steady state
        for run_, suffix in ((1, ""), (2, "_warm")):
            start, cpu = time.perf_counter(), time.process_time()
            battgen_export(path, Path(tmp) / f"dataset{run_}")
            r["battgen_rps" + suffix] = n / (time.perf_counter() - start)
            r["battgen_cpu_rps" + suffix] = n / (time.process_time() - cpu)
            (Path(tmp) / f"hand{run_}").mkdir()
            start, cpu = time.perf_counter(), time.process_time()
            assert hand_path(path, Path(tmp) / f"hand{run_}") == n
            r["hand_rps" + suffix] = n / (time.perf_counter() - start)
            r["hand_cpu_rps" + suffix] = n / (time.process_time() - cpu)
    return r


def report(r: dict[str, float], log: Path) -> None:
    print(f"export of {int(r['records'])} battery_status records in {log.name}'s layout, records/s (wall; CPU):")
    for suffix, what in (("", "first run, imports included"), ("_warm", "second run, in the same process")):
        hand, ours = r["hand_rps" + suffix], r["battgen_rps" + suffix]
        hand_cpu, ours_cpu = r["hand_cpu_rps" + suffix], r["battgen_cpu_rps" + suffix]
        print(f" {what}:")
        print(f"  pyulog -> pandas -> to_parquet {hand / 1e6:8.3f} M/s;  {hand_cpu / 1e6:8.3f} M/s")
        print(
            f"  battgen export                 {ours / 1e6:8.3f} M/s;  {ours_cpu / 1e6:8.3f} M/s  "
            f"{ours / hand:6.2f}x wall, {ours_cpu / hand_cpu:6.2f}x CPU"
        )


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--records", type=int, default=1_000_000)
    parser.add_argument("--log", type=Path, default=DEFAULT_LOG)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.records = min(args.records, 2000)
    results = run(args.log, args.records)
    report(results, args.log)
    return results


if __name__ == "__main__":
    main()
