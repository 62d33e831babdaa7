"""The columns of ``battgen export --failsafe``'s two tables (``events`` and ``replays``, see
:mod:`.failsafe_tables`), each with its doc and unit as Parquet field metadata, for both firmwares' replays."""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import pyarrow as pa

from ..battery.sources import Batch

_TEXT, _INT, _FLOAT = pa.string(), pa.int32(), pa.float64()
# (name, type, doc, unit)
EVENT_COLUMNS: tuple[tuple[str, Any, str, str | None], ...] = (
    ("log", _TEXT, "stable id of the log's content", None),
    ("battery", _INT, "the battery table's battery (0-based)", None),
    ("instance", _INT, "the battery as ArduPilot numbers it (1-based)", None),
    ("t", _FLOAT, "seconds since the log's start, on the battery table's clock", "s"),
    ("replay_t", _FLOAT, "seconds from the log's first reading, as battgen failsafe prints it", "s"),
    ("time", pa.timestamp("us", tz="UTC"), "time of day (UTC), where the log has it", None),
    ("level", _TEXT, "LOW or CRITICAL (PX4: LOW, CRITICAL, EMERGENCY or TIME_LOW)", None),
    ("cause", _TEXT, "voltage or capacity (PX4: charge or time)", None),
    ("value", _FLOAT, "the value that crossed: V, remaining mAh, state of charge 0..1 or s, by cause", None),
    ("threshold", _FLOAT, "the parameter crossed: V or mAh, as value", None),
    ("action", _TEXT, "the vehicle's name for the FS_LOW_ACT / FS_CRT_ACT action", None),
    ("action_code", _INT, "the FS_LOW_ACT / FS_CRT_ACT value", None),
    ("executed", pa.bool_(), "whether the priority rule let the action run", None),
    ("outcome", _TEXT, "what the vehicle does after the handler's fallbacks", None),
    ("priority", _INT, "the action's index in the vehicle's priority list (PX4: null)", None),
    ("statustext", _TEXT, "the STATUSTEXT AP_BattMonitor sends (PX4: commander's notification)", None),
    ("vehicle_type", _TEXT, "the ArduPilot vehicle whose semantics the replay used, or px4", None),
    ("parameters", _TEXT, "the parameters the replay used", None),
)
REPLAY_COLUMNS: tuple[tuple[str, Any, str, str | None], ...] = (
    ("log", _TEXT, "stable id of the log's content", None),
    ("battery", _INT, "the battery table's battery (0-based)", None),
    ("instance", _INT, "the battery as ArduPilot numbers it (1-based)", None),
    ("readings", pa.int64(), "battery readings replayed", None),
    ("level", _TEXT, "the highest level reached: NONE, LOW or CRITICAL (PX4: EMERGENCY too)", None),
    ("vehicle_type", _TEXT, "the ArduPilot vehicle whose semantics the replay used, or px4", None),
    ("parameters", _TEXT, "the parameters the replay used", None),
)


def table_schema(columns: Sequence[tuple[str, Any, str, str | None]], table: str) -> Any:
    fields = []
    for name, typ, doc, unit in columns:
        meta = {"doc": doc} | ({"unit": unit, "quantity": "time"} if unit else {})
        fields.append(pa.field(name, typ, nullable=name != "log", metadata=meta))
    return pa.schema(fields, metadata={"battgen": json.dumps({"table": table, "version": 1})})


EVENTS_SCHEMA = table_schema(EVENT_COLUMNS, "failsafe_events")
REPLAYS_SCHEMA = table_schema(REPLAY_COLUMNS, "failsafe_replays")


def events_table(rows: dict[str, list[Any]], clock: Batch | None) -> Any:
    """The events table of one replay's rows (every column but ``time``, which each row's ``t`` gives where
    ``clock``, a batch of the log, tells the time of day)."""
    offset = None if clock is None else clock.utc_offset_us
    origin = 0 if clock is None else clock.origin_us
    times = [None if offset is None else origin + round(t * 1e6) + offset for t in rows["t"]]
    columns = {**rows, "time": pa.array(times, pa.int64()).cast(EVENTS_SCHEMA.field("time").type)}
    return pa.Table.from_pydict({name: columns[name] for name, *_ in EVENT_COLUMNS}, schema=EVENTS_SCHEMA)
