"""The fleet views: plain SQL over the ``battery`` table of an exported dataset, for DuckDB.

Written into the dataset as ``views.sql`` so any DuckDB can use them (``cd DIR; duckdb -init
views.sql``); ``battgen query`` (:mod:`codegen.apps.fleet_query`) runs them before the user's SQL.
``flights``: one row per flight (a log and a battery instance). ``packs``: one row per pack, by
serial number where the pack reports one, else by vehicle and battery instance.

Internal resistance is estimated at load steps: between consecutive records of a battery less than
:data:`STEP_WINDOW_S` apart whose current changes by at least :data:`STEP_CURRENT_A`, R = -dV/dI;
a flight's value is the median of its positive estimates.
"""

from __future__ import annotations

from pathlib import Path

from .dataset import BATTERY

STEP_CURRENT_A = 2.0
STEP_WINDOW_S = 1.0
VIEWS_FILE = "views.sql"

_BATTERY_VIEW = """CREATE OR REPLACE VIEW battery AS
SELECT * FROM read_parquet('{glob}', hive_partitioning = true, union_by_name = true);
"""

_FLIGHT_VIEWS = f"""-- One row per flight (a log and a battery instance). SI units: V, A, C, J, K, s, Ohm.
CREATE OR REPLACE VIEW flights AS
WITH steps AS (
    SELECT
        *,
        t - lag(t) OVER w AS dt,
        lag(armed) OVER w AS was_armed,
        lag(current) OVER w AS prev_current,
        lag(pack_voltage) OVER w AS prev_voltage
    FROM battery
    WINDOW w AS (PARTITION BY log, battery ORDER BY t)
)
SELECT
    log,
    battery,
    any_value(source) AS source,
    any_value(vehicle) AS vehicle,
    coalesce(CAST(any_value(serial_number) AS VARCHAR), coalesce(any_value(vehicle), log) || '/' || battery) AS pack,
    min(time) AS start_time,
    count(*) AS records,
    max(t) - min(t) AS duration,
    sum(CASE WHEN was_armed THEN dt END) AS duration_armed,
    min(pack_voltage) AS min_voltage,
    min(list_min(cell_voltages)) AS min_cell_voltage,
    max(current) AS peak_current,
    coalesce(max(discharged) - min(discharged), sum(prev_current * dt)) AS charge_used,
    coalesce(max(consumed_energy) - min(consumed_energy), sum(prev_voltage * prev_current * dt)) AS energy_used,
    max(list_max(cell_voltages) - list_min(cell_voltages)) AS max_cell_imbalance,
    max(temperature) AS max_temperature,
    max(state_of_charge) AS start_state_of_charge,
    min(state_of_charge) AS end_state_of_charge,
    max(cycle_count) AS cycle_count,
    min(state_of_health) AS state_of_health,
    median(
        CASE
            WHEN abs(current - prev_current) >= {STEP_CURRENT_A} AND dt <= {STEP_WINDOW_S}
            AND -(pack_voltage - prev_voltage) / (current - prev_current) > 0
            THEN -(pack_voltage - prev_voltage) / (current - prev_current)
        END
    ) AS internal_resistance
FROM steps
GROUP BY log, battery;

-- One row per pack: by serial number where the pack reports one, else by vehicle and battery instance.
CREATE OR REPLACE VIEW packs AS
SELECT
    pack,
    count(*) AS flights,
    min(start_time) AS first_seen,
    max(start_time) AS last_seen,
    max(cycle_count) AS cycle_count,
    sum(charge_used) AS capacity_used,
    sum(energy_used) AS energy_used,
    min(state_of_health) AS state_of_health,
    median(internal_resistance) AS internal_resistance,
    min(min_cell_voltage) AS min_cell_voltage,
    max(max_cell_imbalance) AS max_cell_imbalance,
    max(max_temperature) AS max_temperature
FROM flights
GROUP BY pack;
"""


def views_sql(glob: str) -> str:
    """The views, reading the battery partitions at ``glob``."""
    return _BATTERY_VIEW.format(glob=glob.replace("'", "''")) + "\n" + _FLIGHT_VIEWS


def write_views(out: Path) -> Path:
    """``views.sql`` in the dataset folder, with a path relative to it."""
    path = out / VIEWS_FILE
    text = (
        "-- battgen fleet views: run DuckDB in this folder (duckdb -init views.sql) or use battgen query.\n"
        + views_sql(f"{BATTERY}/*/*.parquet")
    )
    path.write_text(text, encoding="utf-8")
    return path
