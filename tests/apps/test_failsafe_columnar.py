"""The columnar failsafe replay gives exactly the per-sample evaluator's events (the oracle), on every real log
of ../shared with the vehicles' defaults and threshold sets that fire, and on bounded synthetic streams."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from failsafe_streams import ROW, VALUES, table_of, timed
from hypothesis import given, settings
from hypothesis import strategies as st

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


@settings(max_examples=300)
@given(st.lists(ROW, max_size=60), VALUES, st.sampled_from(["copter", "rover", "plane"]), st.booleans())
def test_synthetic_streams_give_the_oracles_events(rows: list[Any], values: dict[str, float], vehicle: str,
                                                   seed: bool) -> None:  # fmt: skip
    _same(table_of(timed(rows)), values, vehicle, ("seed-critical",) if seed else ())
