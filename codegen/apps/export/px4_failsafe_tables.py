"""``battgen export --failsafe`` for a PX4 log: the log replayed through PX4's own battery failsafe
(:func:`..failsafe.px4_replay.replay_px4`, the replay ``battgen failsafe`` runs on a ULog), its events in the
same two tables as an ArduPilot replay (:mod:`.failsafe_tables`).

A row's ``level`` is PX4's (LOW, CRITICAL, EMERGENCY, or TIME_LOW for the remaining-flight-time failsafe),
``cause`` is "charge" or "time", ``value`` and ``threshold`` a state of charge (0..1) or seconds, ``statustext``
the operator's notification commander sends, ``vehicle_type`` "px4"; ``priority`` is null (PX4 has one action per
level, no priority list) and ``executed`` true. The replay reads the ULog's commander topics too, so the log is
read a second time (the export's chunks carry the battery readings only).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pyarrow as pa

from ..battery.sources import Batch
from ..failsafe.px4_levels import Px4Level
from ..failsafe.px4_log import read_px4_log
from ..failsafe.px4_replay import replay_px4
from .failsafe_columns import EVENT_COLUMNS, REPLAYS_SCHEMA, events_table

PX4 = "px4"
OWN = "log parameters (BAT_*, COM_*)"


def px4_tables(
    path: Path, name: str, log: str, given: Mapping[str, float] | None, source: str | None, clock: Batch | None
) -> tuple[Any, Any] | str:
    """The events and replays tables of a PX4 log replayed with its own parameters (``given`` ones on top,
    ``source`` naming them), or a note saying why it was not replayed."""
    try:
        replayed = replay_px4(read_px4_log(path, name), given)
    except ValueError as exc:  # a log without battery_status, or a parameter that is no number
        return f"failsafe not replayed: {exc}"
    parameters = OWN if source is None else f"{OWN}, {source} on top"
    rows: dict[str, list[Any]] = {c[0]: [] for c in EVENT_COLUMNS}
    highest: dict[int, int] = {}
    for e in replayed.events:
        rows["log"].append(log)
        rows["battery"].append(e.battery - 1)
        rows["instance"].append(e.battery)
        rows["t"].append(e.time)  # the data layer's clock, as the battery table's t
        rows["replay_t"].append(e.time)
        rows["level"].append(e.label)
        rows["cause"].append(e.cause)
        rows["value"].append(e.value if e.value == e.value else None)
        rows["threshold"].append(e.threshold)
        rows["action"].append(e.action_name)
        rows["action_code"].append(e.action_code)
        rows["executed"].append(True)
        rows["outcome"].append(e.outcome)
        rows["priority"].append(None)
        rows["statustext"].append(e.text)
        rows["vehicle_type"].append(PX4)
        rows["parameters"].append(parameters)
        if e.cause == "charge":
            highest[e.battery] = max(highest.get(e.battery, 0), int(e.level))
    events = events_table(rows, clock)
    batteries = sorted(replayed.readings)
    replays = pa.Table.from_pydict(
        {
            "log": [log] * len(batteries),
            "battery": [b - 1 for b in batteries],
            "instance": batteries,
            "readings": [replayed.readings[b] for b in batteries],
            "level": [Px4Level(highest.get(b, 0)).name for b in batteries],
            "vehicle_type": [PX4] * len(batteries),
            "parameters": [parameters] * len(batteries),
        },
        schema=REPLAYS_SCHEMA,
    )
    return events, replays
