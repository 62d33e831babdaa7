"""The report's reading of a log (``read_input``): before (the battery view, then every record read a second
time for the validator's findings) and after (the findings from the view's columns,
:mod:`codegen.apps.battery.column_checks`).

"Before" is the same ``_view_input`` with the view read for the mapping's fields only and the column findings
switched off, which is what the report did before; both give the same findings (checked here, as in
``tests/apps/test_column_checks.py``). On every real ULog and tlog of ``../shared`` (a tlog keeps the second read:
its ratio is about 1) and on a synthetic long two-battery ULog (``tests/apps/flight_logs.py``). One run each,
after one warm-up read (schemas loaded, modules imported). Prints the times and the ratio before/after.

Usage: python benchmarks/bench_report_read.py [--seconds S] [--no-real]
"""

from __future__ import annotations

import argparse
import functools
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
SCHEMAS = ROOT / "schemas"


@contextmanager
def _before() -> Iterator[None]:
    """The report as it read before: the view for the mapping's fields, then the second read."""
    from codegen.apps.report import series

    view, columns = series.read_view, series.column_finding_groups

    def mapping_fields_only(*args: Any, **kwargs: Any) -> Any:
        kwargs["all_fields"] = False
        return view(*args, **kwargs)

    series.read_view = mapping_fields_only  # type: ignore[assignment]
    series.column_finding_groups = lambda *a, **k: None  # type: ignore[assignment]
    try:
        yield
    finally:
        series.read_view, series.column_finding_groups = view, columns  # type: ignore[assignment]


def _timed(read: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    out = read()
    return time.perf_counter() - start, out


def measure(path: Path) -> dict[str, float]:
    from codegen.apps.report.series import read_input

    read = functools.partial(read_input, path, SCHEMAS)
    with _before():
        before, old = _timed(read)
    after, new = _timed(read)
    same = repr((old.findings, old.notices, old.unreadable)) == repr((new.findings, new.notices, new.unreadable))
    if not same:
        raise SystemExit(f"{path}: the findings differ before and after")
    findings = float(sum(g.count for g in new.findings))
    return {"records": float(old.records), "findings": findings, "before_s": before, "after_s": after}


def real_logs() -> list[Path]:
    return sorted([*SHARED.rglob("*.ulg"), *SHARED.rglob("*.tlog")]) if SHARED.is_dir() else []


def run(seconds: float = 3600.0, real: bool = True) -> dict[str, dict[str, float]]:
    sys.path.insert(0, str(ROOT / "tests" / "apps"))
    from flight_logs import write_flight

    from codegen.apps.report.series import read_input

    results: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        flight = write_flight(Path(tmp) / "flight.ulg", seconds=seconds, hz=10, packs=2)
        read_input(flight, SCHEMAS)  # warm-up: schemas loaded, generated modules imported
        logs = [(f"synthetic {seconds:.0f} s, 2 packs", flight)]
        logs += [(p.relative_to(SHARED).as_posix(), p) for p in (real_logs() if real else [])]
        print(f"{'log':64} {'records':>8} {'findings':>8} {'before s':>9} {'after s':>8} {'ratio':>6}")
        for label, path in logs:
            r = results[label] = measure(path)
            ratio = r["before_s"] / r["after_s"] if r["after_s"] else float("inf")
            print(
                f"{label[-64:]:64} {r['records']:8.0f} {r['findings']:8.0f} "
                f"{r['before_s']:9.3f} {r['after_s']:8.3f} {ratio:5.2f}x"
            )
    total_before = sum(r["before_s"] for r in results.values())
    total_after = sum(r["after_s"] for r in results.values())
    print(f"all: before {total_before:.2f} s, after {total_after:.2f} s, ratio {total_before / total_after:.2f}x")
    return results


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3600.0, help="the synthetic flight's length")
    parser.add_argument("--no-real", action="store_true", help="the synthetic flight only")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    if args.quick:
        return run(60.0, real=False)
    return run(args.seconds, real=not args.no_real)


if __name__ == "__main__":
    main()
