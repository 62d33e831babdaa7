"""``--raw`` for ArduPilot DataFlash logs: the log's battery records as tables of every field its FMT records
declare."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pyarrow as pa

from ...inputs.dataflash.log import open_log

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
