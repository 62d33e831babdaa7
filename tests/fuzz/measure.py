"""Running a battgen command on hostile input in a subprocess and measuring what it cost.

A memory or time bound is a measurement, not a timed assertion on the fast path: the command runs in a
child process under an address-space cap (so a regression fails the test instead of the machine), and
the test reads the child's own peak resident set size (VmHWM, which the child reports) and its wall time, both
held to generous margins -- tens of times what the command needs, far below what a regression costs.
"""

from __future__ import annotations

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


# The child caps its own address space, runs battgen and writes its peak RSS (VmHWM of its own memory map) to
# the file named first: the rusage of a forked child would also count the parent's pages from before exec.
_WRAPPER = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (int(sys.argv[2]), int(sys.argv[2])))
report, sys.argv = sys.argv[1], ["battgen", *sys.argv[3:]]
try:
    from codegen.cli.main import main
    raise SystemExit(main())
finally:
    with open("/proc/self/status") as status, open(report, "w") as out:
        out.write(next(line.split()[1] for line in status if line.startswith("VmHWM:")))
"""


def run_battgen(*argv: str, seconds: float = 120.0, cwd: Path | None = None) -> Outcome:
    """``battgen argv`` in a child process; killed after ``seconds`` (then ``timed_out``)."""
    with tempfile.TemporaryDirectory() as folder:
        report = Path(folder) / "peak"
        out_path, err_path = Path(folder) / "out", Path(folder) / "err"
        with out_path.open("wb") as out, err_path.open("wb") as err:
            start = time.monotonic()
            proc = subprocess.Popen(
                [sys.executable, "-c", _WRAPPER, str(report), str(CAP_BYTES), *argv], stdout=out, stderr=err,
                cwd=cwd or ROOT,
            )  # fmt: skip
            try:
                proc.wait(timeout=seconds)
                timed_out = False
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
                timed_out = True
            elapsed = time.monotonic() - start
        peak = int(report.read_text()) / 1024 if report.is_file() and report.read_text() else float("nan")
        return Outcome(
            proc.returncode,
            out_path.read_text("utf-8", "replace"),
            err_path.read_text("utf-8", "replace"),
            peak,  # KiB in /proc
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
    assert result.peak_rss_mb < rss_mb, f"peak RSS {result.peak_rss_mb:.0f} MB"  # (NaN: no report, fails too)
    assert result.seconds < seconds, f"took {result.seconds:.1f} s"
