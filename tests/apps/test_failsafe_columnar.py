"""The columnar failsafe replay gives exactly the per-sample evaluator's events (the oracle), on every real log
of ../shared with the vehicles' defaults and threshold sets that fire, and on bounded synthetic streams."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from codegen.apps.battery.sources import Batch
from codegen.apps.battery.view import read_view
from codegen.apps.failsafe.columnar import _per_sample, replay_table
from codegen.apps.failsafe.evaluator import make_failsafe
from codegen.apps.failsafe.logs import SampleTable
from codegen.apps.failsafe.settings import battery_settings
from codegen.apps.failsafe.vehicles import VEHICLES
from codegen.errors import BattgenError

SHARED = Path(__file__).resolve().parents[2].parent / "shared"
SUFFIXES = {".ulg", ".bin", ".tlog", ".log"}


def _logs() -> list[Path]:
    if not SHARED.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"{SHARED} is missing")
        pytest.skip(f"{SHARED} is missing")
    return sorted(p for p in SHARED.rglob("*") if p.is_file() and p.suffix.lower() in SUFFIXES)


def _table(path: Path) -> SampleTable | None:
    table = SampleTable()
    try:
        for chunk in read_view(path):
            table.add(chunk)
    except BattgenError:
        return None  # a file no reader takes (the other tests say why)
    return table


def _parameter_sets(table: SampleTable) -> list[dict[str, float]]:
    """The defaults, then thresholds inside the log's own range (so they fire), voltage and capacity."""
    out: list[dict[str, float]] = [{}]
    _, battery, volts, _, mah, *_ = table.sorted_columns()
    for inst in sorted(set((battery + 1).tolist())):
        head = "BATT_" if inst == 1 else f"BATT{inst}_"
        v = volts[(battery + 1 == inst) & (volts > 0)]
        used = mah[battery + 1 == inst]
        if len(v):
            lo, mid, hi = np.quantile(v, [0.1, 0.5, 0.9]).tolist()
            out.append({head + "LOW_VOLT": hi, head + "CRT_VOLT": mid, head + "LOW_TIMER": 1, head + "FS_LOW_ACT": 2})
            out.append({head + "LOW_VOLT": mid, head + "CRT_VOLT": lo, head + "LOW_TIMER": 0.5,
                        head + "FS_VOLTSRC": 1, head + "FS_CRT_ACT": 5})  # fmt: skip
        if np.isfinite(used).any():
            top = float(np.nanmax(used))
            out.append({head + "CAPACITY": top * 1.2, head + "LOW_MAH": top * 0.6, head + "CRT_MAH": top * 0.3})
    return out


def _same(table: SampleTable, values: dict[str, float], vehicle: str, variants: tuple[str, ...] = ()) -> int:
    v = VEHICLES[vehicle]
    oracle = make_failsafe(battery_settings(values, v), v, variants=variants)
    expected = _per_sample(oracle, table, "x")
    ours = make_failsafe(battery_settings(values, v), v, variants=variants)
    got, counts = replay_table(ours, table, "x")
    assert [e for e, _ in got] == [e for e, _ in expected]
    assert [s for _, s in got] == [s for _, s in expected]
    assert {i: m.failsafe for i, m in ours.monitors.items()} == {i: m.failsafe for i, m in oracle.monitors.items()}
    assert sum(counts.values()) == sum(1 for _ in table.samples())
    return len(expected)


def test_real_logs_give_the_oracles_events() -> None:
    fired = replayed = 0
    for path in _logs():
        table = _table(path)
        if table is None:
            continue
        for values in _parameter_sets(table):
            for vehicle in ("copter", "rover"):
                fired += _same(table, values, vehicle)
                replayed += 1
        fired += _same(table, _parameter_sets(table)[-1], "copter", ("seed-critical",))
    assert replayed > 50 and fired > 20  # the threshold sets do fire


class _Chunk:
    """What SampleTable.add reads of a battery view's chunk."""

    def __init__(self, rows: list[tuple[float, int, float, float, float, float]], battery: int) -> None:
        self.rows = rows
        self.n = len(rows)
        self.battery = np.full(self.n, battery, np.int32)
        self.batch = Batch("test", self.n, {}, np.array([r[0] for r in rows]), np.full(self.n, battery))
        self.batch.armed = np.array([r[5] for r in rows])

    def number(self, concept: str) -> Any:
        column = {"pack_voltage": 2, "current": 3, "discharged": 4}[concept]
        scale = 3.6 if concept == "discharged" else 1.0
        return np.array([r[column] for r in self.rows]) * scale


def _table_of(rows: list[tuple[float, int, float, float, float, float]]) -> SampleTable:
    """A table of one batch a battery (t, battery, V, A, mAh, armed; NaN is unknown)."""
    table = SampleTable()
    for b in sorted({r[1] for r in rows}):
        table.add(_Chunk([r for r in rows if r[1] == b], b))  # type: ignore[arg-type]
    return table


_maybe = st.one_of(st.just(float("nan")), st.floats(9.0, 13.0, allow_nan=False).map(lambda x: round(x, 2)))
_row = st.tuples(
    st.integers(0, 400),  # tenths of a second
    st.integers(0, 1),
    _maybe,
    st.one_of(st.just(float("nan")), st.just(-0.0), st.floats(-5.0, 60.0).map(lambda x: round(x, 1))),
    st.one_of(st.just(float("nan")), st.floats(0.0, 3000.0).map(lambda x: round(x, 0))),
    st.sampled_from([0.0, 1.0, float("nan")]),
)
_values = st.fixed_dictionaries(
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


@settings(max_examples=300)
@given(st.lists(_row, max_size=60), _values, st.sampled_from(["copter", "rover", "plane"]), st.booleans())
def test_synthetic_streams_give_the_oracles_events(rows: list[Any], values: dict[str, float], vehicle: str,
                                                   seed: bool) -> None:  # fmt: skip
    rows = sorted((t / 10, b, v, i, m, a) for t, b, v, i, m, a in rows)
    _same(_table_of(rows), values, vehicle, ("seed-critical",) if seed else ())
