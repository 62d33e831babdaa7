"""Internal resistance from load steps: the one definition ``battgen report`` (its figures) and the
fleet views (``flights.internal_resistance``) both use.

A load step is a pair of consecutive samples of one battery at most :data:`STEP_MAX_DT_S` apart
whose current changes by at least :data:`STEP_FRACTION` of the flight's peak current (its largest
absolute value), and by at least :data:`STEP_MIN_A`; each gives R = -ΔV/ΔI, kept when positive.
The estimate is the median of them, as one step is easily spoiled by a voltage reading lagging the
current. Relative to the peak, the threshold suits a 2 A hobby pack and a 200 A heavy lifter alike.

:func:`step_resistances` computes it over a battery's samples; :func:`resistance_sql` writes the same as
SQL over a table's columns (a window per battery), so the two cannot drift apart.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence

import numpy as np

from .columns import NDArray, floats

STEP_FRACTION = 0.2
STEP_MIN_A = 1.0
STEP_MAX_DT_S = 2.0


def step_threshold(peak_a: float) -> float:
    """The smallest change of current that makes a load step in a flight whose peak is ``peak_a``."""
    return max(STEP_MIN_A, STEP_FRACTION * peak_a)


def neighbour_changes(
    t: Sequence[float] | NDArray, voltage: Sequence[float | None] | NDArray, current: Sequence[float | None] | NDArray
) -> tuple[NDArray, NDArray]:
    """ΔV and ΔI of consecutive samples at most :data:`STEP_MAX_DT_S` apart whose voltages and currents are known,
    in time order (unknown: None, or NaN in an array): the changes a load step, or the report's sag, is read from."""
    dv, di, dt = np.diff(floats(voltage)), np.diff(floats(current)), np.diff(floats(t))
    with np.errstate(invalid="ignore"):
        keep = ~np.isnan(dv) & ~np.isnan(di) & ~(dt > STEP_MAX_DT_S)
    return dv[keep], di[keep]


def step_resistances(
    t: Sequence[float] | NDArray, voltage: Sequence[float | None] | NDArray, current: Sequence[float | None] | NDArray
) -> list[float]:
    """Every load step's -ΔV/ΔI (Ω) of one battery's samples, in time order (unknown: None, or NaN in an array)."""
    amps = floats(current)
    known = np.abs(amps[~np.isnan(amps)])
    if not len(known):
        return []
    dv, di = neighbour_changes(t, voltage, amps)
    step = np.abs(di) >= step_threshold(float(known.max()))
    r = -dv[step] / di[step]
    return [float(x) for x in r[r > 0]]


def internal_resistance(
    t: Sequence[float], voltage: Sequence[float | None], current: Sequence[float | None]
) -> float | None:
    """The median of the load steps' resistances (None without any step)."""
    steps = step_resistances(t, voltage, current)
    return statistics.median(steps) if steps else None


def resistance_sql(dt: str, voltage: str, prev_voltage: str, current: str, prev_current: str, peak: str) -> str:
    """The SQL expression of one sample's load-step resistance (NULL where it is none), given the
    column expressions of a window per battery: the sample's time step ``dt``, its and the previous
    sample's voltage and current, and the battery's ``peak`` absolute current. Aggregate it with
    ``median``."""
    delta_i = f"({current} - {prev_current})"
    resistance = f"-({voltage} - {prev_voltage}) / {delta_i}"
    return (
        f"CASE WHEN {dt} <= {STEP_MAX_DT_S} "
        f"AND abs({delta_i}) >= greatest({STEP_MIN_A}, {STEP_FRACTION} * {peak}) "
        f"AND {resistance} > 0 THEN {resistance} END"
    )
