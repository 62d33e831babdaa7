"""The long fuzzing run: every data-side target of tests/fuzz/targets.py for a share of a time budget, with
counts per target (a nightly job, or before a release).

    python tests/fuzz/long_run.py --minutes 10            # all targets, the budget shared equally
    python tests/fuzz/long_run.py --minutes 2 read-yaml   # some targets
    python tests/fuzz/long_run.py --inputs 100000 --readers   # every reader, 100,000 inputs each (hours)

With ``--minutes``, inputs come from the fuzzers' own strategies, in rounds of 25 fresh random draws. With
``--inputs N``, each target gets N inputs from a seeded mutator (tests/fuzz/fuzz_inputs.py ``mutate``: the same
edits of the same seeds, a hundred times faster than hypothesis, and the same inputs on every run for a seed);
``--readers`` names the targets of every reader (READERS: the data layer of each log and capture kind, the
devicetree and parameter files) and of the export's commit path. Each input runs under a
per-input alarm (a hang becomes a failure) and the process under an address-space cap (a memory blow-up
becomes a MemoryError, a failure). A failing input is shrunk by hypothesis, saved to
``tests/fuzz/crashers/<target>/`` (replayed from then on by test_fuzz_crashers.py) and reported; the exit
status is 1 when anything failed. The pytest form of a long run is ``BATTGEN_FUZZ=long python -m pytest tests/fuzz``.
"""

from __future__ import annotations

import argparse
import hashlib
import logging
import resource
import signal
import sys
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import random

from budget import CRASHERS
from commit_target import commit
from commit_target import seeds as commit_seeds
from fuzz_inputs import inputs, mutate, mutated
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from targets import SUFFIX, TARGETS, seeds
from test_fuzz_data_layer import KINDS as VIEW_KINDS
from test_fuzz_data_layer import _seeds as view_seeds
from test_fuzz_data_layer import view
from test_fuzz_decoders import _FRAMES

from generated.uorb import BatteryStatus

PER_INPUT_SECONDS = 30  # far beyond any input's need: longer is a hang
MEMORY_CAP = 3 << 30


class Hang(BaseException):  # a reader catching Exception must not swallow the alarm (it hid a hang)
    pass


# every reader of a file a stranger hands over, as the long run fuzzes it: the data layer of each log and capture
# kind (read_view, what export, report and query read through), devicetree and parameter files (with the
# validator behind them), and the export's commit path (tests/fuzz/commit_target.py)
READERS: dict[str, tuple[Callable[[bytes], None], Callable[[], list[bytes]]]] = {
    **{
        f"view-{kind}": (lambda data, k=kind: view(k, data), lambda k=kind: view_seeds(k))  # type: ignore[misc]
        for kind in sorted(VIEW_KINDS)
    },
    **{
        f"read-{kind}": (TARGETS[f"read-{kind}"], lambda k=kind: seeds(k))  # type: ignore[misc]
        for kind in ("dts", "dtb", "param", "params")
    },
    "commit": (commit, commit_seeds),
}
MAX_SAVED = 5  # failing inputs saved per target in a run (one defect often fails thousands of inputs)


def fuzz_inputs(target: str, count: int, seed: int = 0, save: Path = CRASHERS) -> tuple[int, list[str], float]:
    """``count`` inputs of the seeded mutator through a reader target: (inputs tried, failures found (saved
    under ``save/<target>/``), the slowest input's seconds). A line of progress every 10,000 inputs."""
    run, make_seeds = READERS[target]
    corpus = make_seeds()
    rng = random.Random(f"{target}:{seed}")
    found: list[str] = []
    kinds: Counter[str] = Counter()  # failures by exception, saved or not
    slowest = 0.0
    for done in range(count):
        if done and done % 10_000 == 0:
            print(f"    {target}: {done} inputs, {len(found)} failures, slowest {slowest:.2f} s", flush=True)
        data = mutate(rng, corpus)
        started = time.monotonic()
        signal.alarm(PER_INPUT_SECONDS)
        try:
            run(data)
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                raise
            digest = hashlib.sha1(data).hexdigest()[:12]
            kinds[type(exc).__name__] += 1
            if len(found) < MAX_SAVED:
                folder = save / target
                folder.mkdir(parents=True, exist_ok=True)
                path = folder / f"found-{digest}.bin"
                path.write_bytes(data)
                found.append(f"{path}: {type(exc).__name__}: {str(exc)[:300]}")
            else:
                found.append(f"(not saved) {digest}: {type(exc).__name__}")
        finally:
            signal.alarm(0)
        slowest = max(slowest, time.monotonic() - started)
    if kinds:
        print(f"    {target}: failures by exception: {dict(kinds)}", flush=True)
    return count, found, slowest


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
        except (Exception, Hang) as exc:  # Hang: a BaseException, so that no reader swallows it
            data = failing[-1]  # the last failing call is hypothesis's shrunk example
            folder = CRASHERS / target
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"found-{hashlib.sha1(data).hexdigest()[:12]}{SUFFIX.get(target.split('-', 1)[1], '.bin')}"
            path.write_bytes(data)
            found.append(f"{path}: {type(exc).__name__}: {str(exc)[:300]}")
        failing.clear()
    return tried, found


def main(argv: list[str] | None = None) -> int:
    logging.disable(logging.WARNING)  # python-can logs each line it skips: millions of lines in a long run
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="the whole run (shared among the targets)")
    parser.add_argument("--inputs", type=int, help="this many inputs of the seeded mutator per reader target")
    parser.add_argument("--seed", type=int, default=0, help="the seeded mutator's seed (with --inputs)")
    parser.add_argument("--save", type=Path, default=CRASHERS, help="where failing inputs go (with --inputs)")
    parser.add_argument("--readers", action="store_true", help=f"every reader target: {', '.join(READERS)}")
    parser.add_argument("targets", nargs="*", help=f"targets (default: all of {', '.join(sorted(TARGETS))})")
    args = parser.parse_args(argv)
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    signal.signal(signal.SIGALRM, _alarm)
    if args.inputs is not None:
        chosen = args.targets or (list(READERS) if args.readers else [])
        return _counted(chosen, args.inputs, args.seed, args.save, parser)
    chosen = args.targets or sorted(TARGETS)
    unknown = [t for t in chosen if t not in TARGETS]
    if unknown:
        parser.error(f"unknown targets: {', '.join(unknown)}")
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


def _counted(chosen: list[str], count: int, seed: int, save: Path, parser: argparse.ArgumentParser) -> int:
    """The ``--inputs`` run: each reader target in turn, one line of counts each."""
    unknown = [t for t in chosen if t not in READERS]
    if not chosen or unknown:
        parser.error(f"--inputs takes reader targets (or --readers): {', '.join(READERS)}")
    failures = 0
    print(f"{'target':<18} {'inputs':>8} {'per s':>7} {'slowest':>8} {'peak MB':>8}  outcome", flush=True)
    for target in chosen:
        started = time.monotonic()
        tried, found, slowest = fuzz_inputs(target, count, seed, save)
        rate = tried / max(time.monotonic() - started, 1e-9)
        failures += len(found)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        outcome = "ok: no traceback, hang or memory blow-up" if not found else f"{len(found)} FAILURES"
        print(f"{target:<18} {tried:>8} {rate:>7.0f} {slowest:>7.2f}s {peak:>8.0f}  {outcome}", flush=True)
        for line in found[:MAX_SAVED]:
            print(f"    {line}", flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
