"""uORB BatteryStatus and ULog: our generated codec and reader against pyulog, in one run.

Run: python benchmarks/bench_ulog.py [--number N] [--records N] [--repeat N]
Prints, best of 5 timeit repeats (--repeat):
- battery_status extraction from whole ULog files, pyulog against ours (parse the file, then the
  topic's columns; also ours as generated instances), records/s and ratio: on the two real PX4
  logs (small: ~20 and ~160 records) and on a synthetic log our writer builds (--records records,
  two battery instances);
- writing that log (records/s);
- per-message decode and encode against a bare precompiled struct.unpack / pack (the floor);
- batch decode of back-to-back 168-byte records, records/s, with numpy and with struct.iter_unpack.
Targets (issue 3): extraction >= 2x pyulog, per-message decode within 3x of the floor, batch decode
>= 5 M records/s.
"""

from __future__ import annotations

import argparse
import struct
import tempfile
import timeit
from collections.abc import Callable
from pathlib import Path

import numpy as np
from pyulog import ULog

from generated import _ulog
from generated.uorb import BatteryStatus

# the shared real PX4 logs, beside the repository (as CI has them)
REAL_LOGS = Path(__file__).resolve().parents[2] / "shared" / "data" / "ulog"

TOPIC = "battery_status"


REPEAT = [5]  # timeit repeats (best of), set by --repeat


def per_op(fn: Callable[[], object], number: int) -> float:
    """Best of REPEAT runs, seconds per call."""
    return min(timeit.repeat(fn, number=number, repeat=REPEAT[0])) / number


def sample(i: int) -> BatteryStatus:
    msg = BatteryStatus(timestamp=1_000_000 + 10_000 * i, connected=True, voltage_v=16.8 - i * 1e-5, cell_count=4)
    msg.current_a, msg.remaining, msg.temperature, msg.id = 12.5 + (i % 7), 0.9 - i * 1e-7, 31.5, 1 + i % 2
    msg.voltage_cell_v[:4] = [4.2 - i * 1e-6] * 4
    return msg


def pyulog_extract(path: str) -> int:
    ulog = ULog(path, message_name_filter_list=[TOPIC])
    return sum(len(d.data["timestamp"]) for d in ulog.data_list)


def ours_extract(path: str, use_numpy: bool) -> int:
    log = _ulog.read(path)
    return sum(len(log.columns(t, m, use_numpy=use_numpy)["timestamp"]) for t, m in log.topics() if t == TOPIC)


def ours_instances(path: str) -> int:
    log = _ulog.read(path)
    return sum(len(log.messages(BatteryStatus, multi_id=m)) for t, m in log.topics() if t == TOPIC)


def same_values(path: str) -> int:
    """Our columns of every battery_status instance against pyulog's, value for value (every field both name);
    the number of columns compared."""
    ulog = ULog(path, message_name_filter_list=[TOPIC])
    theirs = {d.multi_id: d.data for d in ulog.data_list}
    log = _ulog.read(path)
    ours = {m: log.columns(t, m, use_numpy=True) for t, m in log.topics() if t == TOPIC}
    assert sorted(ours) == sorted(theirs), (sorted(ours), sorted(theirs))
    compared = 0
    for multi_id, columns in ours.items():
        for name, values in columns.items():
            if name in theirs[multi_id]:
                np.testing.assert_array_equal(np.asarray(values), theirs[multi_id][name], err_msg=f"{path}: {name}")
                compared += 1
    assert {"timestamp", "voltage_v", "current_a"} <= set(next(iter(ours.values())))
    return compared


def extraction(path: str, number: int, r: dict[str, float], key: str) -> None:
    count = pyulog_extract(path)
    assert count == ours_extract(path, True) == ours_extract(path, False) == ours_instances(path) > 0
    r[f"{key}_columns_compared"] = same_values(path)
    r[f"{key}_records"] = count
    r[f"{key}_pyulog_rps"] = count / per_op(lambda: pyulog_extract(path), number)
    r[f"{key}_ours_numpy_rps"] = count / per_op(lambda: ours_extract(path, True), number)
    r[f"{key}_ours_struct_rps"] = count / per_op(lambda: ours_extract(path, False), number)
    r[f"{key}_ours_instances_rps"] = count / per_op(lambda: ours_instances(path), number)


def run(number: int = 20000, records: int = 200000) -> dict[str, float]:
    r: dict[str, float] = {}
    file_number = max(1, number // 20000)
    for name in ("sample_log_small.ulg", "sample_px4_events.ulg"):
        if (REAL_LOGS / name).is_file():
            extraction(str(REAL_LOGS / name), file_number, r, name.removesuffix(".ulg"))

    msgs = [sample(i) for i in range(records)]
    with tempfile.TemporaryDirectory() as tmp:
        path = str(Path(tmp) / "synthetic.ulg")

        def write() -> None:
            with _ulog.Writer(path, timestamp=1_000_000, info={"sys_name": "bench"}) as w:
                for i, msg in enumerate(msgs):
                    w.write(msg, multi_id=i & 1)

        r["write_rps"] = records / per_op(write, file_number)
        extraction(path, file_number, r, "synthetic")

    data = msgs[0].encode()
    floor = struct.Struct(BatteryStatus.UORB_FORMAT)  # the same layout: one unpack into a tuple, no object
    values = floor.unpack(data)
    r["decode_ours"] = per_op(lambda: BatteryStatus.decode(data), number)
    r["decode_floor"] = per_op(lambda: floor.unpack(data), number)
    r["encode_ours"] = per_op(msgs[0].encode, number)
    r["encode_floor"] = per_op(lambda: floor.pack(*values), number)

    block = b"".join(m.encode() for m in msgs)
    batch_number = max(1, number // 10000)
    r["batch_numpy_rps"] = records / per_op(lambda: BatteryStatus.decode_batch(block, use_numpy=True), batch_number)
    r["batch_struct_rps"] = records / per_op(lambda: BatteryStatus.decode_batch(block, use_numpy=False), batch_number)
    return r


def report(r: dict[str, float]) -> None:
    print("battery_status extraction from a whole ULog (parse + columns), records/s:")
    for key in ("sample_log_small", "sample_px4_events", "synthetic"):
        if f"{key}_records" not in r:
            continue
        base = r[f"{key}_pyulog_rps"]
        compared = int(r[f"{key}_columns_compared"])
        print(f"  {key} ({int(r[f'{key}_records'])} records; {compared} columns the same as pyulog's, value for value)")
        print(f"    pyulog                {base / 1e6:8.3f} M/s")
        for label, name in (("numpy", "numpy"), ("stdlib struct", "struct"), ("instances", "instances")):
            value = r[f"{key}_ours_{name}_rps"]
            print(f"    ours, {label:<15} {value / 1e6:8.3f} M/s  {value / base:6.2f}x pyulog")
    print(f"writing the synthetic log: {r['write_rps'] / 1e6:.3f} M records/s")
    print("per message (168-byte BatteryStatus):")
    for op in ("decode", "encode"):
        ours, floor = r[f"{op}_ours"], r[f"{op}_floor"]
        print(f"  {op}: ours {ours * 1e6:6.2f} us, bare struct {floor * 1e6:6.2f} us  ({ours / floor:.2f}x the floor)")
    print("batch decode into columns, records/s:")
    print(f"  numpy (copied columns) {r['batch_numpy_rps'] / 1e6:8.2f} M/s")
    print(f"  struct.iter_unpack     {r['batch_struct_rps'] / 1e6:8.2f} M/s")


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--number", type=int, default=20000, help="calls per timing of one message")
    parser.add_argument("--records", type=int, default=200000, help="records in the synthetic log and batch")
    parser.add_argument("--repeat", type=int, default=5, help="timeit repeats (the best one counts)")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.number, args.records, args.repeat = 20, 500, 1
    REPEAT[0] = args.repeat
    results = run(args.number, args.records)
    report(results)
    return results


if __name__ == "__main__":
    main()
