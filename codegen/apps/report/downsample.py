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

POINT_BUDGET = 2000  # points per trace; the README and the browser test rely on this number


def planned_length(n: int, budget: int = POINT_BUDGET) -> int:
    """How many points a trace of ``n`` known samples is drawn with."""
    return n if n <= budget else 2 * (budget // 2)


def decimate(
    t: Sequence[float], values: Sequence[float | None], budget: int = POINT_BUDGET
) -> tuple[list[float], list[float | None]]:
    """The points to draw of one trace: all when they fit the budget, else each bucket's min and max."""
    known: list[tuple[float, float]] = [(x, y) for x, y in zip(t, values, strict=True) if y is not None]
    if len(t) <= budget:
        return list(t), list(values)
    buckets = budget // 2
    size = len(known) / buckets if buckets else len(known)
    xs: list[float] = []
    ys: list[float | None] = []
    for b in range(buckets):
        part = known[int(b * size) : int((b + 1) * size)]
        if not part:
            continue
        low = min(part, key=_value)
        high = max(part, key=_value)
        first, second = (low, high) if low[0] <= high[0] else (high, low)
        xs += (first[0], second[0])
        ys += (first[1], second[1])
    return xs, ys


def _value(point: tuple[float, float]) -> float:
    return point[1]
