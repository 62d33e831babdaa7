"""A tlog-shaped stream of MAVLink frames read for its BATTERY_STATUS: battgen's tlog reader against pymavlink's
``MAVLink.parse_buffer`` on the same bytes (issue 30's row: >= 5x ``parse_buffer``).

The stream: ``--frames`` entries (default 200 000), each an 8-byte timestamp and a MAVLink 2 frame, one in four a
HEARTBEAT and the rest BATTERY_STATUS with changing values. Ours: :func:`codegen.inputs.tlog.read_frames` (what
``validate``, ``convert`` and the battery view read a .tlog with: CRC-checked frames decoded to generated
instances). The peer: ``parse_buffer`` over the frames as a user feeds them (the 8-byte stamps cut off), keeping
the BATTERY_STATUS messages. Both in this process, the sides taking turns over ``--rounds`` rounds; CPU seconds min
and median; the decoded voltages, currents and consumed charges of the timed runs compared value for value, and
once more, untimed, every field of every record with its frame's system, component and sequence number.

Usage: python benchmarks/bench_mavlink_stream.py [--frames N] [--rounds N] [--quick]
"""

from __future__ import annotations

import argparse
import io
import struct
from typing import Any

from pymavlink.dialects.v20 import common as pm

try:
    from benchmarks.rounds import in_process, interleaved, machine
except ImportError:  # run as a script: benchmarks/ is the path's first entry
    from rounds import in_process, interleaved, machine  # type: ignore[no-redef]


def stream(frames: int) -> tuple[bytes, list[bytes]]:
    """The tlog bytes and the bare frames in it."""
    mav = pm.MAVLink(None, srcSystem=1, srcComponent=1)
    heartbeat = pm.MAVLink_heartbeat_message(2, 3, 81, 0, 4, 3)
    out, bare = bytearray(), []
    for i in range(frames):
        if i % 4 == 0:
            frame = heartbeat.pack(mav)
        else:
            cells = [4000 + (i % 200), 4010 - (i % 150), 4005, 4012] + [65535] * 6
            msg = pm.MAVLink_battery_status_message(
                0, 0, 1, 2500 + i % 100, cells, 1200 + i % 700, i // 10 % 30000, i % 100000, 90 - i % 90
            )
            frame = msg.pack(mav)
        bare.append(frame)
        out += struct.pack(">Q", 1_700_000_000_000_000 + 100_000 * i) + frame
    return bytes(out), bare


def ours(data: bytes) -> list[tuple[Any, ...]]:
    from codegen.inputs.tlog import StreamStats, read_frames
    from generated.mavlink import BatteryStatus

    stats = StreamStats()
    return [
        (tuple(r.instance.voltages), r.instance.current_battery, r.instance.current_consumed)  # type: ignore[attr-defined]
        for r in read_frames(io.BytesIO(data), "stream", BatteryStatus, stats, timestamps=True)
    ]


def peer(bare: bytes) -> list[tuple[Any, ...]]:
    mav = pm.MAVLink(None)
    mav.robust_parsing = True
    return [
        (tuple(m.voltages), m.current_battery, m.current_consumed)
        for m in mav.parse_buffer(bare) or []
        if m.get_type() == "BATTERY_STATUS"
    ]


def every_value_ours(data: bytes) -> list[tuple[Any, ...]]:
    """Every field of every BATTERY_STATUS record and its frame's header, as read by battgen (untimed)."""
    import dataclasses

    from codegen.inputs.tlog import StreamStats, read_frames
    from generated.mavlink import BatteryStatus

    names = [f.name for f in dataclasses.fields(BatteryStatus)]
    out = []
    for r in read_frames(io.BytesIO(data), "stream", BatteryStatus, StreamStats(), timestamps=True):
        values = (getattr(r.instance, n) for n in names)
        out.append(
            (r.frame.sysid, r.frame.compid, r.frame.seq, *(tuple(v) if isinstance(v, list) else v for v in values))
        )
    return out


def every_value_peer(bare: bytes) -> list[tuple[Any, ...]]:
    """The same from pymavlink's messages, field by field under battgen's names (untimed)."""
    import dataclasses

    from generated.mavlink import BatteryStatus

    names = [f.name for f in dataclasses.fields(BatteryStatus)]
    mav = pm.MAVLink(None)
    mav.robust_parsing = True
    out = []
    for m in mav.parse_buffer(bare) or []:
        if m.get_type() == "BATTERY_STATUS":
            head = m.get_header()
            values = (getattr(m, n) for n in names)
            out.append(
                (head.srcSystem, head.srcComponent, head.seq, *(tuple(v) if isinstance(v, list) else v for v in values))
            )
    return out


def run(frames: int = 200_000, rounds: int = 5) -> dict[str, float]:
    data, bare_frames = stream(frames)
    bare = b"".join(bare_frames)
    ours(data[:4096]), peer(bare[:4096])  # untimed: the imports and the first decodes' caches
    times, outputs = interleaved(
        {
            "battgen tlog reader": lambda: in_process(lambda: ours(data)),
            "pymavlink parse_buffer": lambda: in_process(lambda: peer(bare)),
        },
        rounds,
    )
    if outputs["battgen tlog reader"] != outputs["pymavlink parse_buffer"] or not outputs["battgen tlog reader"]:
        raise RuntimeError("the decoded BATTERY_STATUS values differ")
    if every_value_ours(data) != every_value_peer(bare):
        raise RuntimeError("the BATTERY_STATUS fields or frame headers differ")
    n = len(outputs["battgen tlog reader"])
    print(f"MAVLink stream, {frames:,} frames ({n:,} BATTERY_STATUS), {rounds} interleaved rounds, in-process")
    for name, timing in times.items():
        print(f"  {name:26} {timing.text()}  {frames / timing.median / 1e6:6.2f} M frames/s")
    ratio = times["pymavlink parse_buffer"].median / times["battgen tlog reader"].median
    print(f"  same {n} records' values; battgen / parse_buffer: {ratio:.2f}x   target >= 5x")
    return {"ratio": ratio, "frames_per_s": frames / times["battgen tlog reader"].median}


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--frames", type=int, default=200_000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="2 000 frames, one round (a smoke run)")
    opts = parser.parse_args(argv)
    if opts.quick:
        opts.frames, opts.rounds = min(opts.frames, 2000), 1
    print(f"machine: {machine()}")
    return run(opts.frames, opts.rounds)


if __name__ == "__main__":
    main()
