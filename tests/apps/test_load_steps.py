"""One load-step definition of internal resistance (codegen.apps.battery.load_steps): ``battgen report``'s
figures and the fleet view ``flights`` give the same resistance on the same flight, both the pack
model's; the SQL the view is built from equals the Python definition on arbitrary series."""

from __future__ import annotations

import math
from pathlib import Path

import duckdb
import pytest
from flight_logs import RESISTANCE, write_flight
from hypothesis import given
from hypothesis import strategies as st

from codegen.apps.battery.load_steps import STEP_MAX_DT_S, internal_resistance, resistance_sql
from codegen.apps.export.engine import ExportOptions, export_logs, finish
from codegen.apps.export.query import run_query
from codegen.apps.report.figures import compute
from codegen.apps.report.series import read_input
from codegen.apps.schemas.package import bundled_schemas


def test_report_and_flights_view_agree(tmp_path: Path) -> None:
    log = write_flight(tmp_path / "flight.ulg", seconds=120.0, hz=5.0)
    report = {b.battery: compute(b).internal_resistance_ohm for b in read_input(log, bundled_schemas()).batteries}
    out = tmp_path / "ds"
    assert [r.status for r in export_logs([str(log)], ExportOptions(out))] == ["exported"]
    finish(out)
    view = dict(run_query(out, "SELECT battery, internal_resistance FROM flights ORDER BY battery").rows)
    assert sorted(view) == sorted(report) == [0, 1]
    for battery, ohms in view.items():
        assert ohms == pytest.approx(report[battery], rel=1e-9)
        assert ohms == pytest.approx(RESISTANCE[battery], rel=0.03)  # the pack model's resistance


_SQL = f"""
SELECT median({resistance_sql("dt", "v", "pv", "i", "pi", "peak")})
FROM (
    SELECT t - lag(t) OVER w AS dt, v, lag(v) OVER w AS pv, i, lag(i) OVER w AS pi,
        max(abs(i)) OVER () AS peak
    FROM samples WINDOW w AS (ORDER BY t)
)
"""

_volts = st.one_of(st.none(), st.floats(10.0, 17.0))
_amps = st.one_of(st.none(), st.floats(-5.0, 80.0))


@given(rows=st.lists(st.tuples(st.floats(0.05, 2.0 * STEP_MAX_DT_S), _volts, _amps), min_size=0, max_size=40))
def test_sql_equals_the_python_definition(rows: list[tuple[float, float | None, float | None]]) -> None:
    t, acc = [], 0.0
    for dt, _, _ in rows:
        acc += dt
        t.append(acc)
    volts = [v for _, v, _ in rows]
    amps = [i for _, _, i in rows]
    con = duckdb.connect()
    con.execute("CREATE TABLE samples (t DOUBLE, v DOUBLE, i DOUBLE)")
    if rows:
        con.executemany("INSERT INTO samples VALUES (?, ?, ?)", list(zip(t, volts, amps, strict=True)))
    ((sql,),) = con.execute(_SQL).fetchall()
    expected = internal_resistance(t, volts, amps)
    if expected is None:
        assert sql is None
    else:
        assert sql is not None and math.isclose(sql, expected, rel_tol=1e-9)
