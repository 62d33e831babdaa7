"""``export --failsafe`` and ``report`` against ``export`` on the same logs (issue 22's target: at most 2x).

The logs: the real PX4 logs of ``../shared/data/ulog/`` and one made from a real log by repeating its battery
and arming records (``--records``, default 1 M; built in a temporary folder). Each is exported, exported with
``--failsafe PARAMS`` and reported with ``--params PARAMS`` in this process, and the failsafe replay alone is
timed both ways: columnar (what export and report run) and per-sample (the evaluator it is checked against, the
replay before). Prints the seconds and the ratios to ``export``.

Usage: python benchmarks/bench_failsafe.py [--records N] [--source NAME]
"""

from __future__ import annotations

import argparse
import shutil
import struct
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data" / "ulog"
# thresholds that fire on sample_px4_events.ulg (15.7 .. 16.2 V)
PARAMS = "BATT_LOW_VOLT,16.1\nBATT_CRT_VOLT,15.8\nBATT_LOW_TIMER,1\nBATT_FS_LOW_ACT,2\n"
PARAMS += "BATT_CAPACITY,5000\nBATT_LOW_MAH,1000\n"
HEADER = 16  # the ULog file header
KEEP = ("battery_status", "vehicle_status", "actuator_armed")


def _messages(data: bytes, at: int) -> Iterator[tuple[int, int, bytes]]:
    while at + 3 <= len(data):
        size, kind = struct.unpack_from("<HB", data, at)
        if at + 3 + size > len(data):
            return
        yield at, kind, data[at + 3 : at + 3 + size]
        at += 3 + size


def repeat_ulog(source: Path, target: Path, records: int) -> int:
    """Write ``target``: ``source``'s definitions, then its battery and arming records again and again (timestamps
    shifted by the log's span each time) until ``records`` battery records are written."""
    data = source.read_bytes()
    formats: dict[str, str] = {}
    head_end = HEADER
    in_data = False
    subscribed: dict[int, str] = {}
    adds: list[bytes] = []
    kept: list[tuple[int, bytes]] = []  # (msg_id, payload)
    for at, kind, payload in _messages(data, HEADER):
        if kind == ord("F"):
            name, _, fields = payload.decode("latin-1").partition(":")
            formats[name] = fields
        if kind == ord("A"):
            msg_id = struct.unpack_from("<H", payload, 1)[0]
            name = payload[3:].decode("latin-1")
            if name in KEEP:
                first = formats[name].split(";")[0]
                if first != "uint64_t timestamp":
                    raise ValueError(f"{name}: first field {first!r}, expected the timestamp")
                subscribed[msg_id] = name
                adds.append(data[at : at + 3 + len(payload)])
        elif kind == ord("D"):
            msg_id = struct.unpack_from("<H", payload)[0]
            if msg_id in subscribed:
                kept.append((msg_id, payload))
        if kind in (ord("A"), ord("D"), ord("L"), ord("C"), ord("O"), ord("S"), ord("R")):
            in_data = True
        elif not in_data:
            head_end = at + 3 + len(payload)
    battery = [k for k, (m, _) in enumerate(kept) if subscribed[m] == "battery_status"]
    if not battery:
        raise ValueError(f"{source}: no battery_status record")
    stamps = [struct.unpack_from("<Q", p, 2)[0] for _, p in kept]
    first, last = min(stamps), max(stamps)
    span = last - first + 100_000
    copies = -(-records // len(battery))
    out = bytearray(data[:head_end])
    for a in adds:
        out += a
    written = 0
    for j in range(copies):
        shift = j * span
        for (msg_id, payload), stamp in zip(kept, stamps, strict=True):
            if subscribed[msg_id] == "battery_status":
                if written == records:
                    continue
                written += 1
            body = bytearray(payload)
            struct.pack_into("<Q", body, 2, stamp + shift)
            out += struct.pack("<HB", len(body), ord("D")) + body
    target.write_bytes(bytes(out))
    return written


def _timed(args: list[str]) -> float:
    from codegen.cli.main import main

    start = time.perf_counter()
    code = main(args)
    if code != 0:
        raise SystemExit(f"battgen {' '.join(args)}: exit {code}")
    return time.perf_counter() - start


def replays(log: Path, params: Path) -> tuple[float, float]:
    """The replay alone of a log's samples (what ``--failsafe`` adds to the export's read): the columnar one
    ``export`` and ``report`` use, and the per-sample evaluator it replaced (the oracle). Same events asserted."""
    from codegen.apps.failsafe.columnar import _per_sample, replay_table
    from codegen.apps.failsafe.evaluator import make_failsafe
    from codegen.apps.failsafe.logs import log_samples
    from codegen.apps.failsafe.settings import battery_settings
    from codegen.apps.failsafe.stream import read_parameter_values
    from codegen.apps.failsafe.vehicles import detect_vehicle

    table = log_samples(log)
    values = read_parameter_values(params)
    vehicle = detect_vehicle(values).vehicle
    times, events = [], []
    for replay in (replay_table, _per_sample):
        fs = make_failsafe(battery_settings(values, vehicle), vehicle)
        start = time.perf_counter()
        found = replay(fs, table, log.name)
        times.append(time.perf_counter() - start)
        events.append(found[0] if isinstance(found, tuple) else found)
    if [e for e, _ in events[0]] != [e for e, _ in events[1]]:
        raise SystemExit(f"{log.name}: the columnar replay's events differ from the per-sample evaluator's")
    return times[0], times[1]


def bench(log: Path, tmp: Path) -> dict[str, float]:
    params = tmp / "bench.param"
    params.write_text(PARAMS, encoding="utf-8")
    out: dict[str, float] = {}
    for key, extra in (("export", []), ("export_failsafe", ["--failsafe", str(params)])):
        target = tmp / key
        shutil.rmtree(target, ignore_errors=True)
        out[key] = _timed(["export", str(log), "-o", str(target), "-q", *extra])
    out["report"] = _timed(["report", str(log), "-o", str(tmp / "report.html"), "--params", str(params)])
    out["replay"], out["per_sample_replay"] = replays(log, params)
    e = out["export"]
    print(
        f"{log.name}: export {e:7.2f} s | export --failsafe {out['export_failsafe']:7.2f} s "
        f"({out['export_failsafe'] / e:.2f}x) | report {out['report']:7.2f} s ({out['report'] / e:.2f}x) | "
        f"replay alone: columnar {out['replay']:6.3f} s, per-sample (before) {out['per_sample_replay']:6.2f} s "
        f"({out['per_sample_replay'] / max(out['replay'], 1e-9):.0f}x slower)   target: <= 2x"
    )
    return out


def run(
    records: int = 1_000_000, source: str = "sample_px4_events.ulg", real: bool = True
) -> dict[str, dict[str, float]]:
    sys.path.insert(0, str(ROOT))
    results: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        logs = sorted(SHARED.glob("*.ulg")) if real else []
        big = tmp / f"repeated_{records}.ulg"
        written = repeat_ulog(SHARED / source, big, records)
        print(f"{big.name}: {written:,} battery_status records of {source}, repeated")
        for log in [*logs, big]:
            results[log.name] = bench(log, tmp)
    return results


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--records", type=int, default=1_000_000)
    parser.add_argument("--source", default="sample_px4_events.ulg", help="the real log under ../shared/data/ulog")
    parser.add_argument("--quick", action="store_true", help="2 000 records, the repeated log only (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        return run(min(args.records, 2000), args.source, real=False)
    return run(args.records, args.source)


if __name__ == "__main__":
    main()
