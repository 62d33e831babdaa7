"""How long parsing the bundled schemas and generating the package takes (issue: well under a second).

Run: python benchmarks/bench_generate.py [--repeat N]
Prints the parse and render times per format and in total, best of N runs (pymavlink's import is
counted once, outside the loop, as any long-running process would pay it once).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from codegen.backends.python import render_package
from codegen.frontends.loader import FORMAT_FRONTENDS, frontend, load

ROOT = Path(__file__).resolve().parent.parent
SCHEMAS = ROOT / "schemas"


def best(fn: object, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        fn()  # type: ignore[operator]
        times.append(time.perf_counter() - started)
    return min(times)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeat = 1
    import pymavlink.generator.mavparse  # noqa: F401  (one-off import cost, not per generation)

    for fmt in FORMAT_FRONTENDS:
        sub = SCHEMAS / fmt
        if sub.is_dir():
            seconds = best(lambda sub=sub, fmt=fmt: frontend(fmt).parse_dir(sub), args.repeat)
            print(f"parse {fmt:<11} {seconds * 1000:8.1f} ms")
    schema = load([SCHEMAS])
    render = best(lambda: render_package(schema), args.repeat)
    total = best(lambda: render_package(load([SCHEMAS])), args.repeat)
    print(f"render package    {render * 1000:8.1f} ms ({len(schema.messages)} messages)")
    print(f"parse + render    {total * 1000:8.1f} ms")


if __name__ == "__main__":
    main()
