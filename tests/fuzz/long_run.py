"""The long fuzzing run: every data-side target of tests/fuzz/targets.py for a share of a time budget, with
counts per target (a nightly job, or before a release).

    python tests/fuzz/long_run.py --minutes 10            # all targets, the budget shared equally
    python tests/fuzz/long_run.py --minutes 2 read-yaml   # some targets

Inputs come from the fuzzers' own strategies, in rounds of 25 fresh random draws. Each input runs under a
per-input alarm (a hang becomes a failure) and the process under an address-space cap (a memory blow-up
becomes a MemoryError, a failure). A failing input is shrunk by hypothesis, saved to
``tests/fuzz/crashers/<target>/`` (replayed from then on by test_fuzz_crashers.py) and reported; the exit
status is 1 when anything failed. The pytest form of a long run is ``BATTGEN_FUZZ=long python -m pytest tests/fuzz``.
"""

from __future__ import annotations

import argparse
import hashlib
import resource
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from budget import CRASHERS
from fuzz_inputs import inputs, mutated
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from targets import SUFFIX, TARGETS, seeds
from test_fuzz_decoders import _FRAMES

from generated.uorb import BatteryStatus

PER_INPUT_SECONDS = 30  # far beyond any input's need: longer is a hang
MEMORY_CAP = 3 << 30


class Hang(Exception):
    pass


def strategy(target: str) -> st.SearchStrategy[bytes]:
    if target == "decode-dronecan":
        return st.binary(max_size=120)
    if target == "decode-uorb":
        return st.one_of(st.binary(min_size=168, max_size=168), mutated([BatteryStatus(voltage_v=12.0).encode()]))
    if target == "decode-mavlink":
        return st.one_of(st.binary(max_size=300), mutated([b"".join(_FRAMES), _FRAMES[0]]))
    kind = target.split("-", 1)[1]
    assert kind in SUFFIX, target
    return inputs(kind, seeds(kind))


def _alarm(signum: int, frame: object) -> None:
    raise Hang(f"one input ran for more than {PER_INPUT_SECONDS} s")


def fuzz(target: str, seconds: float) -> tuple[int, list[str]]:
    """Inputs tried and failures found (their saved paths) in ``seconds`` of ``target``."""
    run: Callable[[bytes], None] = TARGETS[target]
    tried = 0
    failing: list[bytes] = []

    def one(data: bytes) -> None:
        nonlocal tried
        tried += 1
        signal.alarm(PER_INPUT_SECONDS)
        try:
            run(data)
        except BaseException:
            failing.append(data)
            raise
        finally:
            signal.alarm(0)

    found: list[str] = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        test = settings(max_examples=25, deadline=None, database=None, suppress_health_check=list(HealthCheck))(
            given(strategy(target))(one)
        )
        try:
            test()
        except Exception as exc:
            data = failing[-1]  # the last failing call is hypothesis's shrunk example
            folder = CRASHERS / target
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"found-{hashlib.sha1(data).hexdigest()[:12]}{SUFFIX.get(target.split('-', 1)[1], '.bin')}"
            path.write_bytes(data)
            found.append(f"{path}: {type(exc).__name__}: {str(exc)[:300]}")
        failing.clear()
    return tried, found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="the whole run (shared among the targets)")
    parser.add_argument("targets", nargs="*", help=f"targets (default: all of {', '.join(sorted(TARGETS))})")
    args = parser.parse_args(argv)
    chosen = args.targets or sorted(TARGETS)
    unknown = [t for t in chosen if t not in TARGETS]
    if unknown:
        parser.error(f"unknown targets: {', '.join(unknown)}")
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    signal.signal(signal.SIGALRM, _alarm)
    share = args.minutes * 60 / len(chosen)
    total, failures = 0, 0
    print(f"{'target':<18} {'inputs':>8} {'per s':>7}  outcome")
    for target in chosen:
        started = time.monotonic()
        tried, found = fuzz(target, share)
        rate = tried / max(time.monotonic() - started, 1e-9)
        total += tried
        failures += len(found)
        outcome = "ok: no traceback, hang or memory blow-up" if not found else f"{len(found)} FAILURES"
        print(f"{target:<18} {tried:>8} {rate:>7.0f}  {outcome}", flush=True)
        for line in found:
            print(f"    {line}")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{'total':<18} {total:>8}          {failures} failures; peak RSS {peak:.0f} MB")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
