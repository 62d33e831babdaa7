"""``battgen export --failsafe``: each log replayed through its firmware's battery failsafe as ``battgen failsafe``
chooses it (:mod:`..failsafe.firmware`): ArduPilot's (:mod:`codegen.apps.failsafe.flight`), or PX4's for a ULog
(:mod:`.px4_failsafe_tables`), its events as tables.

Two tables per replayed log, in the log's partition of ``failsafe/``:

- ``events.parquet``: one row per failsafe transition, the fields ``battgen failsafe --json``
  prints (level, cause, value, threshold, action, outcome, the STATUSTEXT ArduPilot sends, ...),
  with ``t`` on the battery table's clock (seconds since the log's start, so events line up with
  the records) beside ``replay_t`` (the replay's own clock, seconds from the log's first reading,
  as ``battgen failsafe`` prints it) and ``time`` (UTC) where the log has it;
- ``replays.parquet``: one row per battery replayed (readings, the highest level reached, the
  vehicle and the parameters used), so "replayed, no event" differs from "not replayed".

``battery`` is the battery table's battery (0-based); ``instance`` is ArduPilot's number (1-based).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from ...errors import BattgenError
from ..battery.sources import Batch
from ..failsafe.firmware import FIRMWARES, choose_firmware, px4_parameter_count
from ..failsafe.flight import replay_flight
from ..failsafe.logs import SampleTable, own_parameters
from ..failsafe.stream import batt_parameter_count, read_parameter_values
from ..failsafe.vehicles import VEHICLES
from .failsafe_columns import EVENT_COLUMNS, REPLAYS_SCHEMA, events_table
from .px4_failsafe_tables import px4_tables

OWN_PARAMETERS = "log"  # --failsafe log: each ArduPilot log's own parameters (DataFlash PARM, tlog PARAM_VALUE)


@dataclass(frozen=True)
class FailsafeOptions:
    """The replay of a run (picklable): the parameters for every log, or None for each log's own."""

    params: dict[str, float] | None
    source: str  # what the parameters are, as the tables and the manifest record it
    vehicle: str | None = None
    firmware: str | None = None  # px4 or ardupilot; None: as battgen failsafe chooses (the parameters', the log's)

    @property
    def key(self) -> str:
        """Says whether a log's recorded replay was made with these options."""
        return f"{self.source}|vehicle={self.vehicle or 'detected'}|firmware={self.firmware or 'detected'}"


def failsafe_options(given: str, vehicle: str | None = None, firmware: str | None = None) -> FailsafeOptions:
    """The options of ``--failsafe GIVEN``: a parameter file, or ``log`` for each log's own."""
    if vehicle is not None and vehicle not in VEHICLES:
        raise BattgenError(f"expected a vehicle among {', '.join(sorted(VEHICLES))}, got {vehicle!r}")
    if firmware is not None and firmware not in FIRMWARES:
        raise BattgenError(f"expected a firmware among {', '.join(FIRMWARES)}, got {firmware!r}")
    if given == OWN_PARAMETERS:
        return FailsafeOptions(None, "log parameters (PARM)", vehicle, firmware)
    path = Path(given)
    values = read_parameter_values(path)
    if not batt_parameter_count(values) and not px4_parameter_count(values):
        raise BattgenError(
            f"{given}: no BATT*_ parameter (ArduPilot) nor BAT_*/COM_* battery parameter (PX4) ({len(values)} "
            "parameters read): expected battery settings"
        )
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    return FailsafeOptions(values, f"{path.name} ({digest})", vehicle, firmware)


def replay_tables(
    path: Path,
    name: str,
    kind: str,
    log: str,
    options: FailsafeOptions,
    table: SampleTable,
    clock: Batch | None,
) -> tuple[Any, Any] | str:
    """The events and replays tables of one log, replayed from the samples of the chunks the export read
    (``table``), or a note saying why it was not replayed. ``clock``: a batch of the log, for the time of day."""
    if kind == "jsonl":
        return "failsafe not replayed: a JSON Lines file is no flight log battgen failsafe reads"
    firmware, _ = choose_firmware(options.firmware, options.params, options.source, path)
    if firmware == "px4":  # battgen failsafe's choice: PX4's own failsafe for a ULog, unless ArduPilot's is asked
        return px4_tables(path, name, log, options.params, None if options.params is None else options.source, clock)
    values = options.params
    if values is None:
        values = own_parameters(table)
        if values is None:
            return (
                "failsafe not replayed: the log carries no ArduPilot parameters of its own (a DataFlash log's PARM, a "
                "tlog's PARAM_VALUE; give --failsafe PARAMS)"
            )
    replay = replay_flight(table, name, values, options.vehicle)

    def battery(instance: int) -> int:
        return instance - 1

    rows: dict[str, list[Any]] = {c[0]: [] for c in EVENT_COLUMNS}
    for event, sample in replay.events:
        rows["log"].append(log)
        rows["battery"].append(battery(event.battery))
        rows["instance"].append(event.battery)
        rows["t"].append(sample.t)
        rows["replay_t"].append(event.time)
        rows["level"].append(event.level.name)
        for key in ("cause", "value", "threshold", "action", "action_code", "executed", "outcome", "priority"):
            rows[key].append(getattr(event, key))
        rows["statustext"].append(event.ardupilot_text)
        rows["vehicle_type"].append(replay.vehicle)
        rows["parameters"].append(options.source)
    events = events_table(rows, clock)
    replays = pa.Table.from_pydict(
        {
            "log": [log] * len(replay.samples),
            "battery": [battery(i) for i in sorted(replay.samples)],
            "instance": sorted(replay.samples),
            "readings": [replay.samples[i] for i in sorted(replay.samples)],
            "level": [replay.levels[i].name if i in replay.levels else "NONE" for i in sorted(replay.samples)],
            "vehicle_type": [replay.vehicle] * len(replay.samples),
            "parameters": [options.source] * len(replay.samples),
        },
        schema=REPLAYS_SCHEMA,
    )
    return events, replays
