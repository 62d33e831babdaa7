"""The random armed battery streams the failsafe is tested on: hypothesis strategies of sample rows and
BATT_* parameter sets, and the SampleTable a list of rows makes (as a battery view's chunks would). The
columnar replay (tests/apps/test_failsafe_columnar.py) and the Rust crate's failsafe replay
(tests/backends/test_rust_failsafe.py) draw from the same strategies."""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import strategies as st

from codegen.apps.battery.sources import Batch
from codegen.apps.failsafe.logs import SampleTable

Row = tuple[float, int, float, float, float, float]  # t, battery (0-based), V, A, mAh, armed; NaN: unknown


class _Chunk:
    """What SampleTable.add reads of a battery view's chunk."""

    def __init__(self, rows: list[Row], battery: int) -> None:
        self.rows = rows
        self.n = len(rows)
        self.battery = np.full(self.n, battery, np.int32)
        self.batch = Batch("test", self.n, {}, np.array([r[0] for r in rows]), np.full(self.n, battery))
        self.batch.armed = np.array([r[5] for r in rows])

    def number(self, concept: str) -> Any:
        column = {"pack_voltage": 2, "current": 3, "discharged": 4}[concept]
        scale = 3.6 if concept == "discharged" else 1.0
        return np.array([r[column] for r in self.rows]) * scale


def table_of(rows: list[Row]) -> SampleTable:
    """A table of one batch a battery."""
    table = SampleTable()
    for b in sorted({r[1] for r in rows}):
        table.add(_Chunk([r for r in rows if r[1] == b], b))  # type: ignore[arg-type]
    return table


def timed(rows: list[Any]) -> list[Row]:
    """Drawn rows (time in tenths of a second) in time order, the time in seconds."""
    return sorted((t / 10, b, v, i, m, a) for t, b, v, i, m, a in rows)


_maybe = st.one_of(st.just(float("nan")), st.floats(9.0, 13.0, allow_nan=False).map(lambda x: round(x, 2)))
ROW = st.tuples(
    st.integers(0, 400),  # tenths of a second
    st.integers(0, 1),
    _maybe,
    st.one_of(st.just(float("nan")), st.just(-0.0), st.floats(-5.0, 60.0).map(lambda x: round(x, 1))),
    st.one_of(st.just(float("nan")), st.floats(0.0, 3000.0).map(lambda x: round(x, 0))),
    st.sampled_from([0.0, 1.0, float("nan")]),
)
VALUES = st.fixed_dictionaries(
    {
        "BATT_LOW_VOLT": st.sampled_from([0.0, 11.0, 12.0]),
        "BATT_CRT_VOLT": st.sampled_from([0.0, 10.0, 11.5]),
        "BATT_LOW_TIMER": st.sampled_from([0.0, 0.3, 1.0, 2.0]),
        "BATT_CAPACITY": st.sampled_from([0.0, 2000.0, 3300.0]),
        "BATT_LOW_MAH": st.sampled_from([0.0, 1000.0, 2500.0]),
        "BATT_CRT_MAH": st.sampled_from([0.0, 500.0]),
        "BATT_FS_LOW_ACT": st.sampled_from([0, 1, 2, 5]),
        "BATT_FS_CRT_ACT": st.sampled_from([0, 1, 5]),
        "BATT_FS_VOLTSRC": st.sampled_from([0, 1]),
        "BATT_MONITOR": st.sampled_from([4, 3, 0]),
        "BATT2_LOW_VOLT": st.sampled_from([0.0, 11.5]),
        "BATT2_FS_LOW_ACT": st.sampled_from([0, 5]),
        "BATT2_CRT_MAH": st.sampled_from([0.0, 800.0]),
    }
)
