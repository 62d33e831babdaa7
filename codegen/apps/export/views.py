"""The fleet views: plain SQL over the ``battery`` table of an exported dataset, for DuckDB.

Written into the dataset as ``views.sql`` so any DuckDB can use them (``cd DIR; duckdb -init
views.sql``); ``battgen query`` (:mod:`codegen.apps.export.query`) runs them before the user's SQL.
``flights``: one row per flight (a log and a battery instance). ``packs``: one row per pack, by
serial number where the pack reports one, else by vehicle and battery instance. A flight's records, times,
voltages, current, armed time, charge and energy used are the figures of :mod:`codegen.apps.battery.figures`, the
definition ``battgen report`` shows too.

Internal resistance is estimated at load steps as ``battgen report`` does (one definition, in
:mod:`codegen.apps.battery.load_steps`): consecutive records of a battery at most 2 s apart whose current
changes by at least 20 % of the flight's peak (and 1 A) give R = -dV/dI; a flight's value is the
median of its positive estimates.

``failsafe_events`` and ``failsafe_replays`` are the tables ``battgen export --failsafe`` writes
(:mod:`.failsafe_tables`); ``flights`` gives per flight the highest level reached, the number of
events, when LOW and CRITICAL were first reached (``t``) and the last action run (null where the
log was not replayed).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..battery.figures import WINDOW_SQL, flight_sql
from ..battery.load_steps import resistance_sql
from .dataset import BATTERY, table_glob
from .durable import write_atomic
from .failsafe_columns import EVENTS_SCHEMA, REPLAYS_SCHEMA
from .manifest import committed

_STEP = resistance_sql("dt", "pack_voltage", "prev_voltage", "current", "prev_current", "peak_abs_current")
VIEWS_FILE = "views.sql"

# a log id is hex, and one of digits only would be read as a number by hive partitioning: typed as text
_BATTERY_VIEW = """CREATE OR REPLACE VIEW battery AS
SELECT * FROM read_parquet({files}, hive_partitioning = true, hive_types = {{'log': VARCHAR}},
    union_by_name = true);
"""

_FLIGHT_VIEWS = f"""-- One row per flight (a log and a battery instance). SI units: V, A, C, J, K, s, Ohm.
CREATE OR REPLACE VIEW flights AS
WITH steps AS (
    SELECT
        *,
        {WINDOW_SQL},
        max(abs(current)) OVER (PARTITION BY log, battery) AS peak_abs_current
    FROM battery
    WINDOW w AS (PARTITION BY log, battery ORDER BY t)
),
per_flight AS (
SELECT
    log,
    battery,
    any_value(source) AS source,
    any_value(vehicle) AS vehicle,
    coalesce(CAST(any_value(serial_number) AS VARCHAR), coalesce(any_value(vehicle), log) || '/' || battery) AS pack,
    min(time) AS start_time,
{flight_sql()},
    min(list_min(cell_voltages)) AS min_cell_voltage,
    max(list_max(cell_voltages) - list_min(cell_voltages)) AS max_cell_imbalance,
    max(temperature) AS max_temperature,
    max(state_of_charge) AS start_state_of_charge,
    min(state_of_charge) AS end_state_of_charge,
    max(cycle_count) AS cycle_count,
    min(state_of_health) AS state_of_health,
    median({_STEP}) AS internal_resistance
FROM steps
GROUP BY log, battery
),
failsafe AS (
    SELECT
        log,
        battery,
        count(*) AS events,
        min(CASE WHEN level = 'LOW' THEN t END) AS first_low,
        min(CASE WHEN level = 'CRITICAL' THEN t END) AS first_critical,
        arg_max(outcome, replay_t) FILTER (WHERE executed) AS outcome
    FROM failsafe_events
    GROUP BY log, battery
)
SELECT
    per_flight.*,
    replay.level AS failsafe_level,
    CASE WHEN replay.level IS NOT NULL THEN coalesce(failsafe.events, 0) END AS failsafe_events,
    failsafe.first_low AS failsafe_first_low,
    failsafe.first_critical AS failsafe_first_critical,
    failsafe.outcome AS failsafe_outcome
FROM per_flight
LEFT JOIN failsafe_replays AS replay USING (log, battery)
LEFT JOIN failsafe USING (log, battery);

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
    max(max_temperature) AS max_temperature,
    sum(failsafe_events) AS failsafe_events
FROM flights
GROUP BY pack;
"""


_DUCKDB_TYPES = {"string": "VARCHAR", "int32": "INTEGER", "int64": "BIGINT", "double": "DOUBLE", "bool": "BOOLEAN"}


def _table_view(name: str, files: list[str], schema: Any) -> str:
    """A view over Parquet files, or, where there are none yet, an empty one with the same columns
    (DuckDB refuses an empty list)."""
    if files:
        return f"""CREATE OR REPLACE VIEW {name} AS
SELECT * FROM read_parquet({_list(files)}, hive_partitioning = true, hive_types = {{'log': VARCHAR}},
    union_by_name = true);
"""
    columns = ", ".join(f"CAST(NULL AS {_DUCKDB_TYPES.get(str(f.type), 'TIMESTAMPTZ')}) AS {f.name}" for f in schema)
    return f"CREATE OR REPLACE VIEW {name} AS SELECT {columns} WHERE false;\n"


def _quote(text: str) -> str:
    return text.replace("'", "''")


def _list(files: list[str]) -> str:
    return "[" + ", ".join(f"'{_quote(f)}'" for f in files) + "]"


def views_sql(out: Path, *, relative: bool = False) -> str:
    """The views over the dataset at ``out`` (``relative``: paths relative to it): each reads the files its
    logs' markers name (:func:`.manifest.committed`), so a version being written or one just replaced is
    never read, and a log is seen whole or not at all. The failsafe views are empty where no log was
    replayed; a dataset without logs gets its battery table's glob (DuckDB says it matches nothing)."""
    files = committed(out)
    prefix = "" if relative else out.as_posix() + "/"
    battery = [prefix + f for f in files[BATTERY]]
    return "\n".join(
        (
            _BATTERY_VIEW.format(
                files=_list(battery) if battery else f"'{_quote(table_glob(out, BATTERY, relative=relative))}'"
            ),
            "-- The failsafe replay (battgen export --failsafe): its events, and the batteries replayed.",
            _table_view("failsafe_events", [prefix + f for f in files["events"]], EVENTS_SCHEMA),
            _table_view("failsafe_replays", [prefix + f for f in files["replays"]], REPLAYS_SCHEMA),
            _FLIGHT_VIEWS,
        )
    )


def write_views(out: Path) -> Path:
    """``views.sql`` in the dataset folder, with paths relative to it: the files committed now (a later
    export writes it again); replaced in one rename."""
    path = out / VIEWS_FILE
    text = (
        "-- battgen fleet views: run DuckDB in this folder (duckdb -init views.sql) or use battgen query.\n"
        + views_sql(out, relative=True)
    )
    write_atomic(path, text)
    return path
