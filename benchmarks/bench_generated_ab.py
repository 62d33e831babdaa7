"""The generated codecs and validators of an earlier commit against today's, in one process, interleaved.

A change to the Python backend may cost the generated code at most a set share of its speed; comparing two
runs on a busy machine measures the machine. Here the earlier commit's ``generated/`` (``git archive``) is
imported under another name beside the current one, and every operation alternates between the two within
each round (best of the rounds), on the data of bench_dronecan, bench_mavlink and bench_validate.

Usage: python benchmarks/bench_generated_ab.py [--commit REV] [--rounds N] [--number N]
Prints, per operation, microseconds per call for the commit and for the working tree, and their ratio.
"""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys
import tarfile
import tempfile
import time
import timeit
from collections.abc import Callable
from io import BytesIO
from pathlib import Path
from types import ModuleType
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
OLD = "generated_before"  # the earlier package's name here: its modules import each other relatively


def unpack_commit(rev: str, into: Path) -> None:
    """``generated/`` of ``rev`` into ``into``/generated_before (the package alone: the C and Rust stay out)."""
    data = subprocess.run(
        ["git", "archive", "--format=tar", rev, "generated"], cwd=ROOT, capture_output=True, check=True
    ).stdout
    with tarfile.open(fileobj=BytesIO(data)) as tar:
        members = [m for m in tar.getmembers() if m.name.endswith(".py") and "/c/" not in m.name]
        tar.extractall(into, members=members, filter="data")
    (into / "generated").rename(into / OLD)


def operations(old: str, new: str) -> dict[str, tuple[Callable[[], object], Callable[[], object]]]:
    """Each operation as (earlier, current), on the same data; asserts the two give the same results."""

    sys.path.insert(0, str(ROOT / "benchmarks"))  # the other benchmarks' data, the same values as theirs
    try:
        from bench_dronecan import VALUES
        from bench_mavlink import FIELDS
        from bench_validate import INVALID, VALID
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))

    def mod(pkg: str, name: str) -> ModuleType:
        return importlib.import_module(f"{pkg}.{name}")

    info = [mod(p, "dronecan.uavcan.equipment.power").BatteryInfo for p in (old, new)]
    mav = [mod(p, "mavlink").BatteryStatus for p in (old, new)]
    status = [mod(p, "uorb").BatteryStatus for p in (old, new)]
    payload = info[1](**VALUES).encode()
    assert payload == info[0](**VALUES).encode(), "the two DroneCAN encoders disagree"
    frame = mav[1](**FIELDS).encode_frame()
    assert frame == mav[0](**FIELDS).encode_frame(), "the two MAVLink encoders disagree"
    body = mav[1](**FIELDS).encode(truncate=False)
    good = [c.from_dict(VALID) for c in status]
    bad = [c.from_dict(INVALID) for c in status]
    assert [str(v) for v in bad[0].validate()] == [str(v) for v in bad[1].validate()], "the validators disagree"

    def pair(make: Callable[[int], Callable[[], object]]) -> tuple[Callable[[], object], Callable[[], object]]:
        return make(0), make(1)

    return {
        "dronecan build+encode": pair(lambda i: lambda: info[i](**VALUES).encode()),
        "dronecan decode": pair(lambda i: lambda: info[i].decode(payload)),
        "mavlink build+encode frame": pair(lambda i: lambda: mav[i](**FIELDS).encode_frame()),
        "mavlink decode_frame": pair(lambda i: lambda: mav[i].decode_frame(frame)),
        "mavlink payload decode": pair(lambda i: lambda: mav[i].decode(body)),
        "uorb validate (valid)": pair(lambda i: good[i].validate),
        "uorb validate (invalid)": pair(lambda i: bad[i].validate),
        "uorb from_dict+validate": pair(lambda i: lambda: status[i].from_dict(VALID).validate()),
    }


def measure(ops: dict[str, Any], rounds: int, number: int) -> dict[str, tuple[float, float]]:
    """Best CPU microseconds per call of (earlier, current); the order alternates round by round."""
    best = {name: [float("inf"), float("inf")] for name in ops}
    for r in range(rounds):
        for name, fns in ops.items():
            for side in (0, 1) if r % 2 else (1, 0):
                # CPU time: on a shared machine, the time the process waits for a core is not the code's
                t = timeit.timeit(fns[side], number=number, timer=time.process_time) / number * 1e6
                best[name][side] = min(best[name][side], t)
    return {name: (b[0], b[1]) for name, b in best.items()}


def main(argv: list[str] | None = None) -> dict[str, tuple[float, float]]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--commit", default="HEAD", help="the earlier commit (default: HEAD, against the work tree)")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--number", type=int, default=2000, help="calls per timing")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.rounds, args.number = 1, 20
    with tempfile.TemporaryDirectory(prefix="battgen-ab-") as tmp:
        unpack_commit(args.commit, Path(tmp))
        sys.path.insert(0, tmp)
        try:
            results = measure(operations(OLD, "generated"), args.rounds, args.number)
        finally:
            sys.path.remove(tmp)
            for name in [m for m in sys.modules if m == OLD or m.startswith(OLD + ".")]:
                del sys.modules[name]
    print(f"generated/ of {args.commit} against the work tree, best of {args.rounds} interleaved rounds")
    print(f"  {'operation':<28} {'before us':>10} {'now us':>10} {'now/before':>11}")
    for name, (before, now) in results.items():
        print(f"  {name:<28} {before:10.2f} {now:10.2f} {now / before:11.3f}")
    return results


if __name__ == "__main__":
    main()
