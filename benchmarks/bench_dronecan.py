"""DroneCAN uavcan.equipment.power.BatteryInfo: our generated codec against pydronecan.

Runs both on the same values in one process and prints per-operation times and ratios:
* build + encode (construct the object from values, serialise it with tail array optimisation);
* decode (payload bytes -> a new object);
* our decode against a floor: a hand-written, precompiled ``struct`` + shift decode of the same
  layout into a tuple (what any decoder of this type must at least do).

Usage: python benchmarks/bench_dronecan.py [--number N]
"""

from __future__ import annotations

import argparse
import struct
import timeit
from collections.abc import Callable
from typing import Any

from generated.dronecan.uavcan.equipment.power import BatteryInfo

VALUES: dict[str, Any] = {
    "temperature": 301.5,
    "voltage": 15.9,
    "current": -12.25,
    "average_power_10sec": 190.0,
    "remaining_capacity_wh": 61.5,
    "full_charge_capacity_wh": 88.0,
    "hours_to_full_charge": 0.0,
    "status_flags": 1,
    "state_of_health_pct": 93,
    "state_of_charge_pct": 70,
    "state_of_charge_pct_stdev": 3,
    "battery_id": 0,
    "model_instance_id": 31337,
    "model_name": b"ACME 4S2P Li-ion 10Ah",
}

_FLOOR = struct.Struct("<7eIBI")


def floor_decode(data: bytes) -> tuple[Any, ...]:
    """The bare minimum for this layout: one precompiled struct call, shifts for the packed bits."""
    t0, t1, t2, t3, t4, t5, t6, g, bid, mid = _FLOOR.unpack_from(data)
    return (
        t0, t1, t2, t3, t4, t5, t6,
        (g & 0xFF) | ((g >> 13) & 0x7) << 8,
        ((g >> 22) & 0x3) | ((g >> 8) & 0x1F) << 2,
        (g >> 31) | ((g >> 16) & 0x3F) << 1,
        (g >> 24) & 0x7F,
        bid, mid, data[23:],
    )  # fmt: skip


def timings(ops: dict[str, tuple[Callable[[], object], int]], rounds: int = 5) -> dict[str, float]:
    """Microseconds per call, best of ``rounds``; the rounds interleave every op, so a busy
    machine slows ours and the peer alike and the ratios stay meaningful."""
    best = dict.fromkeys(ops, float("inf"))
    for _ in range(rounds):
        for name, (fn, number) in ops.items():
            best[name] = min(best[name], timeit.timeit(fn, number=number) / number * 1e6)
    return best


def run(number: int = 20000, ref_number: int | None = None) -> dict[str, float]:
    import dronecan
    from dronecan import transport

    ref_number = ref_number or max(1, number // 100)
    ref_cls = dronecan.uavcan.equipment.power.BatteryInfo
    ref_values = dict(VALUES, model_name=VALUES["model_name"].decode())

    def ours_encode() -> bytes:
        return BatteryInfo(**VALUES).encode()

    def ref_encode() -> bytes:
        return bytes(transport.bytes_from_bits(ref_cls(**ref_values)._pack(True)))

    payload = ours_encode()
    assert payload == ref_encode(), "the two encoders disagree"

    def ours_decode() -> BatteryInfo:
        return BatteryInfo.decode(payload)

    def ref_decode() -> Any:
        obj = ref_cls()
        obj._unpack(transport.bits_from_bytes(payload), True)
        return obj

    decoded = ours_decode()
    assert decoded.encode() == payload
    assert floor_decode(payload)[7:] == (
        decoded.status_flags,
        decoded.state_of_health_pct,
        decoded.state_of_charge_pct,
        decoded.state_of_charge_pct_stdev,
        decoded.battery_id,
        decoded.model_instance_id,
        decoded.model_name,
    )

    t = timings(
        {
            "ours_encode": (ours_encode, number),
            "ref_encode": (ref_encode, ref_number),
            "ours_decode": (ours_decode, number),
            "ref_decode": (ref_decode, ref_number),
            "floor_decode": (lambda: floor_decode(payload), number),
        }
    )
    print(f"DroneCAN BatteryInfo ({len(payload)} bytes payload, TAO on)")
    print(f"  build+encode  ours {t['ours_encode']:8.2f} us   pydronecan {t['ref_encode']:9.1f} us"
          f"   ratio {t['ref_encode'] / t['ours_encode']:6.1f}x")  # fmt: skip
    print(f"  decode        ours {t['ours_decode']:8.2f} us   pydronecan {t['ref_decode']:9.1f} us"
          f"   ratio {t['ref_decode'] / t['ours_decode']:6.1f}x")  # fmt: skip
    print(f"  decode floor  {t['floor_decode']:8.2f} us (struct + shifts into a tuple);"
          f" ours is {t['ours_decode'] / t['floor_decode']:.2f}x the floor")  # fmt: skip
    return t


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--number", type=int, default=20000, help="calls per timing run of our codec")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    return run(min(args.number, 200) if args.quick else args.number)


if __name__ == "__main__":
    main()
