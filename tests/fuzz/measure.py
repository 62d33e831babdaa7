"""Running a battgen command on hostile input in a subprocess and measuring what it cost.

A memory or time bound is a measurement, not a timed assertion on the fast path: the command runs in a
child process under an address-space cap (so a regression fails the test instead of the machine), and
the test reads the child's own peak resident set size (``os.wait4``'s rusage) and its wall time, both
held to generous margins -- tens of times what the command needs, far below what a regression costs.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CAP_BYTES = 3 << 30  # RLIMIT_AS of the child: numpy and friends reserve address space they never touch


@dataclass(frozen=True)
class Outcome:
    code: int  # the exit status (negative: killed by that signal)
    stdout: str
    stderr: str
    peak_rss_mb: float  # the child's own peak resident set size
    seconds: float  # wall time
    timed_out: bool


def _cap() -> None:  # runs in the child before exec
    resource.setrlimit(resource.RLIMIT_AS, (CAP_BYTES, CAP_BYTES))


def run_battgen(*argv: str, seconds: float = 120.0, cwd: Path | None = None) -> Outcome:
    """``python -m codegen argv`` in a child process; killed after ``seconds`` (then ``timed_out``)."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.monotonic()
        proc = subprocess.Popen(
            [sys.executable, "-m", "codegen", *argv], stdout=out, stderr=err, cwd=cwd or ROOT, preexec_fn=_cap
        )
        timed_out = False
        while True:  # wait4 rather than wait(): it gives this child's own rusage
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > seconds:
                proc.kill()
                timed_out = True
                pid, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.02)
        elapsed = time.monotonic() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return Outcome(
            proc.returncode,
            out.read().decode("utf-8", "replace"),
            err.read().decode("utf-8", "replace"),
            usage.ru_maxrss / 1024,  # KiB on Linux
            elapsed,
            timed_out,
        )


def assert_bounded(
    result: Outcome, *, codes: tuple[int, ...] = (1, 2), rss_mb: float = 400, seconds: float = 60
) -> None:
    """A clear ending: an expected exit status, no traceback, peak RSS and wall time within the margins."""
    assert not result.timed_out, f"still running after {result.seconds:.0f} s"
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    assert result.code in codes, (result.code, result.stderr[-2000:])
    assert result.peak_rss_mb < rss_mb, f"peak RSS {result.peak_rss_mb:.0f} MB"
    assert result.seconds < seconds, f"took {result.seconds:.1f} s"
