"""The figures of one flight of one battery, defined once: over a battery's columns here (``battgen report``, its
JSON, the consistency tests) and as SQL for the fleet views (``flights`` in :mod:`codegen.apps.export.views`).

A flight is the records of one battery of one log in time order (``t``: seconds since the log's start; a number
NaN where the record does not know it). SI units, as the concepts have them.

- ``records``, ``first_t``, ``last_t``: every record counts, whatever it knows.
- ``armed_s``: the time between consecutive records whose earlier one is armed (the state holds until the next
  record says otherwise); None where the log says nothing of arming.
- ``min_voltage``, ``max_voltage``, ``max_current``: over the known values.
- ``charge_used`` (C) and ``energy_used`` (J): from the battery's own counter (``discharged``,
  ``consumed_energy``: the fuel gauge or the autopilot's integrator) where it gives at least two known values,
  not all zero, as the last known minus the first (a charging battery lowers it); else the trapezoid integral of
  the current (of V·I) over the intervals whose two ends are known. A counter that stays 0 is one the firmware
  does not keep (PX4 without a current sensor), so it is not taken for "nothing used".

The SQL mirrors each step; the two sum floating point in other orders, so they agree to rounding, not to the bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .columns import NDArray


@dataclass(frozen=True)
class FlightFigures:
    records: int
    first_t: float | None  # s since the log's start
    last_t: float | None
    armed_s: float | None
    min_voltage: float | None  # V
    max_voltage: float | None
    max_current: float | None  # A
    charge_used: float | None  # C
    energy_used: float | None  # J

    @property
    def duration_s(self) -> float:
        return 0.0 if self.first_t is None or self.last_t is None else self.last_t - self.first_t


def _float(value: object) -> float | None:
    return None if value is None else float(value)  # type: ignore[arg-type]


def counter_used(values: NDArray) -> float | None:
    """Last known minus first known value of a counter with at least two known values, not all zero."""
    known = values[~np.isnan(values)]
    if len(known) < 2 or not (known != 0).any():
        return None
    return float(known[-1] - known[0])


def trapezoid(t: NDArray, values: NDArray) -> float | None:
    """The integral over consecutive records whose two values are known (None without any such interval)."""
    if len(t) < 2:
        return None
    a, b = values[:-1], values[1:]
    both = ~np.isnan(a) & ~np.isnan(b)
    if not both.any():
        return None
    return float(np.sum(((a + b) / 2 * np.diff(t))[both]))


def armed_time(t: NDArray, armed: NDArray | None) -> float | None:
    """Seconds from each armed record to the next (None where no record knows the arming state)."""
    if armed is None or len(t) < 2 or np.isnan(armed[:-1]).all():
        return None
    return float(np.sum(np.diff(t)[armed[:-1] == 1.0]))


def _extreme(values: NDArray, pick: str) -> float | None:
    known = values[~np.isnan(values)]
    if not len(known):
        return None
    return float(known.max() if pick == "max" else known.min())


def flight_figures(
    t: NDArray,
    voltage: NDArray,
    current: NDArray,
    discharged: NDArray,
    consumed_energy: NDArray,
    armed: NDArray | None = None,
) -> FlightFigures:
    """The figures of one battery's records (float64 arrays, NaN unknown; ``armed`` 1.0 / 0.0 / NaN, or None for
    a log without arming state), taken in time order (a stable sort: records of one time keep the log's order)."""
    order = np.argsort(t, kind="stable")
    t, voltage, current = t[order], voltage[order], current[order]
    discharged, consumed_energy = discharged[order], consumed_energy[order]
    armed = None if armed is None else armed[order]
    charge = counter_used(discharged)
    energy = counter_used(consumed_energy)
    return FlightFigures(
        records=len(t),
        first_t=_float(t[0]) if len(t) else None,
        last_t=_float(t[-1]) if len(t) else None,
        armed_s=armed_time(t, armed),
        min_voltage=_extreme(voltage, "min"),
        max_voltage=_extreme(voltage, "max"),
        max_current=_extreme(current, "max"),
        charge_used=charge if charge is not None else trapezoid(t, current),
        energy_used=energy if energy is not None else trapezoid(t, voltage * current),
    )


# -- the same in SQL ---------------------------------------------------------------------------------------------

# the window columns the aggregates below read, over one battery's records ordered by t (DuckDB, a view's CTE)
WINDOW_SQL = """t - lag(t) OVER w AS dt,
        lag(armed) OVER w AS was_armed,
        lag(current) OVER w AS prev_current,
        lag(pack_voltage) OVER w AS prev_voltage"""


def _counter_sql(column: str) -> str:
    return (
        f"CASE WHEN count({column}) >= 2 AND max(abs({column})) > 0 THEN "
        f"arg_max({column}, t) FILTER (WHERE {column} IS NOT NULL) - "
        f"arg_min({column}, t) FILTER (WHERE {column} IS NOT NULL) END"
    )


# column -> aggregate, per (log, battery): the names the ``flights`` view has always had
FLIGHT_SQL = {
    "records": "count(*)",
    "first_t": "min(t)",
    "last_t": "max(t)",
    "duration": "max(t) - min(t)",
    "duration_armed": "CASE WHEN count(was_armed) > 0 THEN coalesce(sum(CASE WHEN was_armed THEN dt END), 0) END",
    "min_voltage": "min(pack_voltage)",
    "max_voltage": "max(pack_voltage)",
    "peak_current": "max(current)",
    "charge_used": f"coalesce({_counter_sql('discharged')}, sum((current + prev_current) / 2 * dt))",
    "energy_used": (
        f"coalesce({_counter_sql('consumed_energy')}, "
        "sum((pack_voltage * current + prev_voltage * prev_current) / 2 * dt))"
    ),
}


def flight_sql(indent: str = "    ") -> str:
    """The aggregates of :data:`FLIGHT_SQL` as a SELECT list's lines."""
    return ",\n".join(f"{indent}{expr} AS {name}" for name, expr in FLIGHT_SQL.items())
