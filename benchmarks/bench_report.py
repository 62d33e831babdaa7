"""The report of a long flight: battgen report against the hand path people take (pyulog + plotly, every point).

On the same synthetic one-hour, 10 Hz, two-battery ULog (``tests/apps/flight_logs.py``):

* battgen: ``battgen report`` in process (read every record, validate it, convert it to the shared concepts,
  compute the figures, decimate to the point budget, write the page);
* by hand: pyulog reads battery_status, plotly draws voltage, current and the cells of each battery with every
  sample and writes a self-contained HTML file (``include_plotlyjs=True``).

Prints both times, the ratio, and the page sizes and the points each page holds (what the browser must draw).

Usage: python benchmarks/bench_report.py [--seconds S]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def hand_path(log: Path, out: Path) -> int:
    """pyulog + plotly with every sample: the points drawn."""
    from plotly import graph_objects as go
    from plotly.subplots import make_subplots
    from pyulog import ULog

    ulog = ULog(str(log), ["battery_status"])
    points = 0
    fig = make_subplots(rows=3, cols=1, shared_xaxes=True)
    for data in ulog.data_list:
        t = data.data["timestamp"] / 1e6
        fig.add_trace(go.Scatter(x=t, y=data.data["voltage_v"], name=f"V {data.multi_id}"), row=1, col=1)
        fig.add_trace(go.Scatter(x=t, y=data.data["current_a"], name=f"I {data.multi_id}"), row=2, col=1)
        points += 2 * len(t)
        for c in range(6):
            fig.add_trace(go.Scatter(x=t, y=data.data[f"voltage_cell_v[{c}]"], name=f"cell {c}"), row=3, col=1)
            points += len(t)
    fig.write_html(str(out), include_plotlyjs=True)
    return points


def run(seconds: float = 3600.0) -> dict[str, float]:
    sys.path.insert(0, str(ROOT / "tests" / "apps"))
    from flight_logs import write_flight

    from codegen.cli.main import main

    with tempfile.TemporaryDirectory() as tmp:
        log = write_flight(Path(tmp) / "flight.ulg", seconds=seconds, hz=10, packs=2)
        ours_out, hand_out = Path(tmp) / "ours.html", Path(tmp) / "hand.html"
        start = time.perf_counter()
        assert main(["report", str(log), "-o", str(ours_out)]) == 0
        ours = time.perf_counter() - start
        start = time.perf_counter()
        hand_points = hand_path(log, hand_out)
        hand = time.perf_counter() - start
        figures = {
            "records": seconds * 10 * 2,
            "ours_s": ours,
            "hand_s": hand,
            "ours_kib": ours_out.stat().st_size / 1024,
            "hand_kib": hand_out.stat().st_size / 1024,
            "hand_points": float(hand_points),
        }
    print(f"flight: {seconds:.0f} s at 10 Hz, 2 batteries ({figures['records']:.0f} battery_status records)")
    print(
        f"battgen report: {ours:6.2f} s, page {figures['ours_kib']:,.0f} KiB (decimated, every row and cell, "
        "validated, figures)"
    )
    print(f"pyulog+plotly:  {hand:6.2f} s, page {figures['hand_kib']:,.0f} KiB ({hand_points:,} points drawn)")
    print(f"ratio: {hand / ours:.2f}x the hand path's time")
    return figures


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    parser.add_argument("--seconds", type=float, default=3600.0)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    return run(60.0 if args.quick else args.seconds)


if __name__ == "__main__":
    main()
