"""Keeping long logs responsive: at most a point budget per plotted trace.

A one-hour flight at 10 Hz has 36,000 samples per column; a browser draws a few thousand points per trace
without effort. A trace with more samples than the budget is cut into ``budget // 2`` buckets of consecutive
samples and each bucket keeps its lowest and highest value, in time order (min-max decimation): every peak and
dip stays visible -- a voltage sag or a current spike is exactly what the report is for -- and the trace has
exactly ``budget`` points (fewer when values are unknown: a decimated trace leaves unknown samples out, while
a trace within the budget keeps them as gaps).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..battery.columns import NDArray, floats

POINT_BUDGET = 2000  # points per trace; the README and the browser test rely on this number


def planned_length(n: int, budget: int = POINT_BUDGET) -> int:
    """How many points a trace of ``n`` known samples is drawn with."""
    return n if n <= budget else 2 * (budget // 2)


def decimate(
    times: Sequence[float] | NDArray, trace: Sequence[float | None] | NDArray, budget: int = POINT_BUDGET
) -> tuple[list[float], list[float | None]]:
    """The points to draw of one trace (unknown: None, or NaN in an array): all when they fit the budget (unknown
    ones as gaps, None), else each bucket's min and max."""
    t, values = np.asarray(times, np.float64), floats(trace)
    if len(t) <= budget:
        return [float(x) for x in t.tolist()], [None if y != y else y for y in values.tolist()]
    known = ~np.isnan(values)
    xs_known, ys_known = t[known], values[known]
    buckets = budget // 2
    size = len(ys_known) / buckets if buckets else len(ys_known)
    xs: list[float] = []
    ys: list[float | None] = []
    for b in range(buckets):
        lo, hi = int(b * size), int((b + 1) * size)
        if hi <= lo:
            continue
        part = ys_known[lo:hi]
        low, high = lo + int(np.argmin(part)), lo + int(np.argmax(part))  # the first of equal values, as min()
        first, second = (low, high) if xs_known[low] <= xs_known[high] else (high, low)
        xs += (float(xs_known[first]), float(xs_known[second]))
        ys += (float(ys_known[first]), float(ys_known[second]))
    return xs, ys
