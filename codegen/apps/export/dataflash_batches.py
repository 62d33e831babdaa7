"""ArduPilot DataFlash logs (.bin) for the export: the battery monitor readings (``BAT``, older
``BAT2``/``CURR``/``CURR2``) of :mod:`codegen.inputs.dataflash`, one batch per instance.

DataFlash has no message schema in the IR (its layout is in each log's own FMT records), so there is
no mapping file to apply: the four values the reader gives -- ``Volt`` V, ``Curr`` A, ``CurrTot``
mAh, ``RemPct`` % -- become concepts here, with the factors taken from the IR's unit registry.
A value the log lacks is unknown. ``t`` is the log's ``TimeUS`` (time since boot, when the log
starts); ``armed`` comes from ``ARM`` / ``EV`` records; ``time`` (UTC) from the first ``GPS``
record with a week (``GWk``/``GMS`` against its ``TimeUS``, as pymavlink's DataFlash reader sets
its clock), where the log has one.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from ...inputs.dataflash import ArmingRecord, BatteryRecord, GpsClock, open_log, timed_flight_records
from ...ir.units import unit
from .catalog import Catalog
from .columns import ConceptColumn, NDArray, empty_columns
from .sources import Batch, as_of

MESSAGE = "dataflash.BAT"
# reader attribute -> (DataFlash field, unit, concept)
FIELDS = (
    ("voltage_v", "Volt", "V", "pack_voltage"),
    ("current_a", "Curr", "A", "current"),
    ("consumed_mah", "CurrTot", "mAh", "discharged"),
    ("remaining_pct", "RemPct", "%", "state_of_charge"),
)


def dataflash_batches(path: Path, name: str, catalog: Catalog) -> list[Batch]:
    """Every battery instance of a DataFlash log as a batch with its concepts filled."""
    log = open_log(path, name)
    readings: dict[int, list[BatteryRecord]] = {}
    arming: list[ArmingRecord] = []
    clock: GpsClock | None = None
    for item in timed_flight_records(log):
        if isinstance(item, ArmingRecord):
            arming.append(item)
        elif isinstance(item, GpsClock):
            clock = clock or item
        else:
            readings.setdefault(item.instance, []).append(item)
    arm_t = np.array([a.time_s for a in arming], np.float64)
    arm_v = np.array([a.armed for a in arming], bool)
    out: list[Batch] = []
    for instance, rows in sorted(readings.items()):
        n = len(rows)
        columns: dict[str, NDArray] = {}
        for attr, field, _, _ in FIELDS:
            columns[field] = np.array([np.nan if getattr(r, attr) is None else getattr(r, attr) for r in rows])
        t = np.array([r.time_s for r in rows], np.float64)
        batch = Batch(MESSAGE, n, columns, t, np.full(n, instance))
        batch.concepts = _concepts(catalog, columns, n)
        if clock is not None:  # the log's clock against UTC, from its first GPS record with a week
            batch.utc_offset_us = clock.utc_us - clock.time_us
            batch.time_us = np.round(t * 1e6).astype(np.int64) + batch.utc_offset_us
        if len(arming):
            batch.armed = as_of(arm_t, arm_v, t)
        if log.skipped_notes:
            batch.notes.append(f"{len(log.skipped_notes)} notes from the DataFlash reader (skipped data)")
        out.append(batch)
    return out


def _concepts(catalog: Catalog, columns: dict[str, NDArray], n: int) -> dict[str, ConceptColumn]:
    out = empty_columns(catalog.concepts, n)
    for _, field, symbol, concept in FIELDS:
        target = out[concept]
        assert target.concept.unit is not None
        mul, add = unit(symbol).factor_to(target.concept.unit)
        values = columns[field]
        target.set(values * mul + add, ~np.isnan(values))
    return out


RAW_TYPES = ("BAT", "BATT", "BAT2", "CURR", "CURR2", "BCL", "BCL2")  # the readings and the cell voltages


def dataflash_raw_tables(path: Path, name: str, log: str) -> list[tuple[str, Any]]:
    """``--raw``: the log's battery records (``BAT``, older ``BAT2``/``CURR``/``CURR2``, and the
    cell voltages ``BCL``) as tables of every field the log's FMT records declare, by type
    (``dataflash.BAT``, ...), values as pymavlink's DataFlash reader gives them (its format
    multipliers applied, nothing else). Context first: ``log``, ``instance`` (``Inst`` /
    ``Instance``, else 0) and ``t`` (``TimeUS`` in seconds)."""
    rows: dict[str, list[dict[str, Any]]] = {}
    for msg in open_log(path, name).messages(RAW_TYPES):
        rows.setdefault(msg.type, []).append(
            {
                "log": log,
                "instance": int(msg.fields.get("Inst", msg.fields.get("Instance", 0)) or 0),
                "t": msg.time_s,
                **{k: _plain(v) for k, v in msg.fields.items()},
            }
        )
    out = []
    for kind, records in sorted(rows.items()):
        table = pa.Table.from_pylist(records)
        context = {"log": pa.string(), "instance": pa.int32(), "t": pa.float64()}
        table = table.cast(pa.schema([pa.field(f.name, context.get(f.name, f.type)) for f in table.schema]))
        meta = {"battgen": json.dumps({"message": f"dataflash.{kind}", "source": "DataFlash FMT records"})}
        out.append((f"dataflash.{kind}", table.replace_schema_metadata(meta)))
    return out


def _plain(value: Any) -> Any:
    """A field value for Arrow: text as str (pymavlink gives some char arrays as bytes)."""
    if isinstance(value, bytes):
        return value.split(b"\0", 1)[0].decode("utf-8", "replace")
    return value
