"""MAVLink BATTERY_STATUS: our generated codec against pymavlink, on the same data in one run.

Run: python benchmarks/bench_mavlink.py [--number N] [--records N]
Prints, best of 5 timeit repeats: build + encode a frame, decode a frame (ours generically by
message id and through the class), payload decode against a bare precompiled struct.unpack (the
floor), and batch decode of fixed-size records in records per second (numpy and struct paths).
Targets (issue 3): frame decode >= 3x pymavlink, payload decode within 3x of the floor, batch
decode >= 5 M records/s.
"""

from __future__ import annotations

import argparse
import struct
import timeit
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import common as pm

from generated import _mavlink as rt
from generated.mavlink import BatteryStatus

FIELDS: dict[str, Any] = {
    "id": 1, "battery_function": 2, "type": 1, "temperature": 2512, "voltages": [4012, 4020, 4018, 4015] + [65535] * 6,
    "current_battery": 1234, "current_consumed": 1500, "energy_consumed": 8000, "battery_remaining": 77,
    "time_remaining": 1200, "charge_state": 1, "voltages_ext": [0, 0, 0, 0], "mode": 0, "fault_bitmask": 0,
}  # fmt: skip


def per_op(fn: Callable[[], object], number: int) -> float:
    """Best of five runs, seconds per call."""
    return min(timeit.repeat(fn, number=number, repeat=5)) / number


def run(number: int = 20000, records: int = 200000) -> dict[str, float]:
    mav = pm.MAVLink(None, srcSystem=1, srcComponent=1)
    args = [FIELDS[name] for name in pm.MAVLink_battery_status_message.fieldnames]
    frame = BatteryStatus(**FIELDS).encode_frame()
    assert frame == pm.MAVLink_battery_status_message(*args).pack(pm.MAVLink(None, 1, 1)), "not the same bytes"
    payload = BatteryStatus(**FIELDS).encode(truncate=False)
    floor = struct.Struct(pm.MAVLink_battery_status_message.unpacker.format)  # the same layout, no object built
    assert floor.size == len(payload)
    block = payload * records

    r: dict[str, float] = {}
    r["pack_pymavlink"] = per_op(lambda: pm.MAVLink_battery_status_message(*args).pack(mav), number)
    r["pack_ours"] = per_op(lambda: BatteryStatus(**FIELDS).encode_frame(), number)
    r["parse_pymavlink"] = per_op(lambda: mav.decode(bytearray(frame)), number)
    r["parse_ours"] = per_op(lambda: rt.decode_message(frame), number)
    r["parse_ours_class"] = per_op(lambda: BatteryStatus.decode_frame(frame), number)
    r["decode_payload_ours"] = per_op(lambda: BatteryStatus.decode(payload), number)
    r["decode_payload_floor"] = per_op(lambda: floor.unpack(payload), number)
    batch_number = max(1, number // 10000)
    r["batch_struct_rps"] = records / per_op(lambda: BatteryStatus.decode_batch(block, use_numpy=False), batch_number)
    try:
        import numpy  # noqa: F401
    except ImportError:
        pass
    else:
        r["batch_numpy_rps"] = records / per_op(lambda: BatteryStatus.decode_batch(block, use_numpy=True), batch_number)
    return r


def _vs(label: str, peer: str, theirs: float, ours: float, note: str = "") -> str:
    return (
        f"{label:<36} {peer:<9} {theirs * 1e6:7.2f} us   ours {ours * 1e6:6.2f} us   {theirs / ours:5.1f}x faster{note}"
    )


def report(r: dict[str, float]) -> str:
    floor, ours = r["decode_payload_floor"], r["decode_payload_ours"]
    lines = [
        _vs("pack  (build + encode frame)", "pymavlink", r["pack_pymavlink"], r["pack_ours"]),
        _vs("parse (frame -> instance)", "pymavlink", r["parse_pymavlink"], r["parse_ours"], " (target >= 3x)"),
        _vs("parse via BatteryStatus.decode_frame", "pymavlink", r["parse_pymavlink"], r["parse_ours_class"]),
        f"{'payload decode':<36} {'struct':<9} {floor * 1e6:7.2f} us   ours {ours * 1e6:6.2f} us"
        f"   {ours / floor:5.2f}x the floor (target <= 3x)",
        f"{'batch decode (struct.iter_unpack)':<36} {r['batch_struct_rps'] / 1e6:7.2f} M records/s",
    ]
    if "batch_numpy_rps" in r:
        lines.append(f"{'batch decode (numpy)':<36} {r['batch_numpy_rps'] / 1e6:7.2f} M records/s (target >= 5 M)")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser()
    parser.add_argument("--number", type=int, default=20000, help="calls per timing run")
    parser.add_argument("--records", type=int, default=200000, help="records per batch")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    opts = parser.parse_args(argv)
    if opts.quick:
        opts.number, opts.records = 50, 500
    results = run(opts.number, opts.records)
    print(report(results))
    return results


if __name__ == "__main__":
    main()
