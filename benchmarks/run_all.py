"""Every benchmark in one run, then issue 30's table: what the user runs against what they would write instead, the
figure (the median of the benchmark's rounds), the target and whether the median meets it.

Each benchmark is called by its ``main(argv)`` (``--quick`` passed on with ``--quick``: tiny sizes, one round, for
a smoke run whose figures mean nothing). A benchmark that fails is reported and makes the exit status 1; one whose
tools are missing (gcc, cargo, arm-none-eabi-gcc) says so and the others go on. The machine (cores, load average)
is printed at the start and at the end: the figures of a loaded machine are to be read with its load.

Usage: python benchmarks/run_all.py [--quick] [--only NAME,...] [--skip NAME,...]
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))  # the benchmarks import each other as top-level modules (rounds)
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))  # and some import generated/ from the repository

from rounds import machine  # noqa: E402

# the table's rows first, then the rest; bench_validate and bench_convert give main(argv) and --quick too
TABLE = [
    "bench_startup",
    "bench_validate",
    "bench_convert",
    "bench_failsafe_stream",
    "bench_export_log",
    "bench_mavlink_stream",
]
OTHERS = [
    "bench_mavlink",
    "bench_tlog",
    "bench_ulog",
    "bench_ulog_layouts",
    "bench_fleet",
    "bench_can",
    "bench_dronecan",
    "bench_dataflash",
    "bench_failsafe",
    "bench_px4_failsafe",
    "bench_report",
    "bench_report_read",
    "bench_export_memory",
    "bench_generate",
    "bench_generated_ab",
    "bench_c_convert",
    "bench_c_sizes",
    "bench_c_speed",
    "bench_rust",
]
ALL = TABLE + OTHERS


def _get(figures: dict[str, Any], *keys: str) -> float | None:
    """The first of ``keys`` a benchmark returned."""
    for key in keys:
        value = figures.get(key)
        if isinstance(value, int | float):
            return float(value)
    return None


Row = tuple[str, str, Callable[[dict[str, dict[str, Any]]], tuple[str, bool | None]]]


def _ratio_row(
    bench: str, keys: tuple[str, ...], target: float
) -> Callable[[dict[str, dict[str, Any]]], tuple[str, bool | None]]:
    def row(results: dict[str, dict[str, Any]]) -> tuple[str, bool | None]:
        value = _get(results.get(bench, {}), *keys)
        if value is None:
            return f"not reported by {bench} (keys {', '.join(keys)})", None
        return f"{value:.2f}x (target >= {target:g}x)", value >= target

    return row


def _startup(results: dict[str, dict[str, Any]]) -> tuple[str, bool | None]:
    r = results.get("bench_startup", {})
    help_s, one_s = _get(r, "help: battgen / ulog_info battgen_s"), _get(r, "one record / ulog_info battgen_s")
    peer = _get(r, "help: battgen / ulog_info peer_s")
    if help_s is None or one_s is None or peer is None:
        return "not reported by bench_startup", None
    text = f"--help {help_s:.3f} s (ulog_info {peer:.3f} s), validate one record {one_s:.3f} s wall"
    return text + " (targets <= 0.15 s, <= 0.3 s)", help_s <= 0.15 and one_s <= 0.3


def _failsafe(results: dict[str, dict[str, Any]]) -> tuple[str, bool | None]:
    r = results.get("bench_failsafe_stream", {})
    ratio, rate = _get(r, "ratio"), _get(r, "samples_per_s")
    if ratio is None or rate is None:
        return "not reported by bench_failsafe_stream", None
    return f"{ratio:.2f}x, {rate / 1e6:.2f} M samples/s (targets >= 4x, >= 2 M/s)", ratio >= 4 and rate >= 2e6


ROWS: list[Row] = [
    ("battgen --help, any command on one record", "ulog_info, mavlogdump.py", _startup),
    (
        "battgen validate, 100k JSON Lines",
        "json + fastjsonschema",
        _ratio_row("bench_validate", ("cli x_vs_script", "cli_x_vs_script"), 2),
    ),
    (
        "from_dict + validate() in Python",
        "fastjsonschema",
        _ratio_row("bench_validate", ("api x_vs_fastjsonschema", "x_vs_fastjsonschema"), 2),
    ),
    (
        "battgen convert, 100k JSON Lines",
        "a per-record loop",
        _ratio_row("bench_convert", ("cli x_vs_loop", "cli x_vs_script", "cli_x_vs_loop"), 1),
    ),
    ("battgen failsafe, 1 M samples", "json + ArduPilot's rules loop", _failsafe),
    (
        "battgen export, one real log",
        "pyulog -> pandas -> to_parquet",
        _ratio_row("bench_export_log", ("ratio",), 1),
    ),
    (
        "MAVLink stream of BATTERY_STATUS",
        "pymavlink parse_buffer",
        _ratio_row("bench_mavlink_stream", ("ratio",), 5),
    ),
]


def run_one(name: str, quick: bool) -> tuple[dict[str, Any] | None, str | None]:
    """A benchmark's figures, or why there are none."""
    for folder in (HERE, HERE.parent):  # a caller may have taken them off the path since this module loaded
        if str(folder) not in sys.path:
            sys.path.insert(0, str(folder))
    try:
        module = importlib.import_module(name)
        with contextlib.redirect_stderr(io.StringIO()) as err:
            result = module.main(["--quick"] if quick else [])
    except SystemExit as exc:  # a benchmark whose tools are missing exits with a sentence
        if exc.code == 2:  # argparse's: an option its main does not know
            return None, "FAILED: its main(argv) does not take " + ("--quick" if quick else "no arguments")
        return None, f"skipped ({exc})"
    except Exception:  # one failing benchmark is reported; the others still run
        return None, "FAILED:\n" + traceback.format_exc(limit=3)
    if err.getvalue().strip():
        print(err.getvalue().rstrip())
    return (result if isinstance(result, dict) else {}), None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="every benchmark in its --quick mode (a smoke run)")
    parser.add_argument("--only", help="comma-separated benchmark names (default: all)")
    parser.add_argument("--skip", default="", help="comma-separated benchmark names to leave out")
    opts = parser.parse_args(argv)
    names = opts.only.split(",") if opts.only else ALL
    names = [n for n in names if n not in opts.skip.split(",")]
    unknown = sorted(set(names) - set(ALL))
    if unknown:
        parser.error(f"unknown benchmarks: {', '.join(unknown)} (known: {', '.join(ALL)})")
    start_machine = machine()
    print(f"machine at start: {start_machine}")
    results: dict[str, dict[str, Any]] = {}
    failed: list[str] = []
    for name in names:
        print(f"\n=== {name}{' --quick' if opts.quick else ''}", flush=True)
        began = time.perf_counter()
        figures, problem = run_one(name, opts.quick)
        if figures is not None:
            results[name] = figures
        elif problem is not None:
            print(problem)
            if problem.startswith("FAILED"):
                failed.append(name)
        print(f"=== {name}: {time.perf_counter() - began:.1f} s", flush=True)
    print(f"\nissue 30's table ({'quick run: sizes too small to mean anything' if opts.quick else 'medians'}):")
    print(f"  {'what the user runs':<42} {'what they would write instead':<32} figure; met")
    for what, peer, row in ROWS:
        text, met = row(results)
        verdict = "n/a" if met is None else ("met" if met else "NOT met")
        print(f"  {what:<42} {peer:<32} {text}; {verdict}")
    print(f"machine at start: {start_machine}")
    print(f"machine at end:   {machine()}")
    if failed:
        print(f"failed: {', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
