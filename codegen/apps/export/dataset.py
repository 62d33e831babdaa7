"""The dataset folder: Hive-style partitions by log, written so a crash leaves no half log.

Layout under the output folder::

    battery/log=<id>/part-0.parquet        the normalised table (one file per log)
    raw/<message>/log=<id>/part-0.parquet  --raw: every field as decoded, sentinels kept
    failsafe/log=<id>/events.parquet       --failsafe: the replay's events (and replays.parquet)
    logs/<id>.json                         what was exported from the log (its marker: present = done)
    views.sql                              the DuckDB views (see codegen.apps.fleet_query)
    dataset.json                           the partitioning: {"partition": "log"} or "day"

``--partition day`` puts a ``day=YYYY-MM-DD`` level (UTC, from the log's first record with a time
of day; Hive's ``__HIVE_DEFAULT_PARTITION__``, read as null, where the log has none) above each
``log=<id>`` folder.

A log's files are written into a temporary folder beside them and moved into place, its marker
last: a log whose marker exists is complete, and ``battgen export`` skips it when it meets the same
content again.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ...errors import BattgenError
from ...ir import ArrayType, Message, PrimitiveKind, PrimitiveType, StringType
from .sources import Batch

BATTERY = "battery"
RAW = "raw"
LOGS = "logs"
LAYOUT_FILE = "dataset.json"
PARTITIONS = ("log", "day")
UNKNOWN_DAY = "__HIVE_DEFAULT_PARTITION__"  # Hive's name for a null partition value; DuckDB and pyarrow read it so


def layout(out: Path) -> str:
    """How the dataset at ``out`` is partitioned: ``log`` (``<table>/log=<id>/``) or ``day``
    (``<table>/day=YYYY-MM-DD/log=<id>/``); a dataset from before the choice existed is by log."""
    try:
        data = json.loads((out / LAYOUT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return "log"
    found = data.get("partition") if isinstance(data, dict) else None
    return found if found in PARTITIONS else "log"


def claim_layout(out: Path, partition: str) -> None:
    """Record the partitioning of a new dataset; refuse another one for an existing dataset (the
    two layouts in one folder would not read back as one table)."""
    if partition not in PARTITIONS:
        raise BattgenError(f"expected a partitioning among {', '.join(PARTITIONS)}, got {partition!r}")
    has_logs = (out / LOGS).is_dir() and any((out / LOGS).glob("*.json"))
    if has_logs and layout(out) != partition:
        raise BattgenError(
            f"{out}: the dataset is partitioned by {layout(out)}; give --partition {layout(out)} or a new folder"
        )
    out.mkdir(parents=True, exist_ok=True)
    (out / LAYOUT_FILE).write_text(json.dumps({"partition": partition}) + "\n", encoding="utf-8")


def partition_of(partition: str, log: str, day: str | None) -> str:
    """A log's partition folder under each table: ``log=<id>`` or ``day=<YYYY-MM-DD>/log=<id>``."""
    if partition == "day":
        return f"day={day or UNKNOWN_DAY}/log={log}"
    return f"log={log}"


def table_glob(out: Path, table: str, file_name: str = "*.parquet", *, relative: bool = False) -> str:
    """The files of a table in the dataset's layout; ``relative``: a path relative to ``out``."""
    depth = "*/*" if layout(out) == "day" else "*"
    return f"{'' if relative else out.as_posix() + '/'}{table}/{depth}/{file_name}"


def marker(out: Path, log: str) -> Path:
    return out / LOGS / f"{log}.json"


def is_exported(out: Path, log: str) -> bool:
    return marker(out, log).is_file()


def exported_manifest(out: Path, log: str) -> dict[str, Any] | None:
    """What the marker of an exported log records (None: not exported, or a marker unreadable)."""
    try:
        data = json.loads(marker(out, log).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _raw_type(ftype: object) -> Any:
    if isinstance(ftype, ArrayType):
        inner = _raw_type(ftype.element)
        if isinstance(ftype.element, StringType) or inner == pa.binary():
            return pa.list_(pa.string())
        return pa.list_(inner, ftype.capacity) if ftype.capacity and not ftype.dynamic else pa.list_(inner)
    if isinstance(ftype, PrimitiveType):
        if ftype.kind is PrimitiveKind.FLOAT:
            return pa.float64() if ftype.bits == 64 else pa.float32()
        if ftype.kind is PrimitiveKind.BOOL:
            return pa.bool_()
        if ftype.kind in (PrimitiveKind.INT, PrimitiveKind.UINT):
            bits = next(b for b in (8, 16, 32, 64) if b >= ftype.bits)
            return (
                pa.int64()
                if bits == 64
                else getattr(pa, f"{'u' if ftype.kind is PrimitiveKind.UINT else ''}int{bits}")()
            )
        if ftype.kind is PrimitiveKind.CHAR:
            return pa.string()
    return pa.string()


def raw_table(message: Message, batch: Batch, log: str) -> Any:
    """One batch as its message's own table: every field as decoded (arrays as lists)."""
    arrays = [
        pa.array(np.full(batch.n, log, object), type=pa.string()),
        pa.array(np.asarray(batch.instance, np.int32), type=pa.int32()),
        pa.array(batch.t, type=pa.float64(), mask=np.isnan(batch.t)),
    ]
    fields = [pa.field("log", pa.string()), pa.field("instance", pa.int32()), pa.field("t", pa.float64())]
    for f in message.fields:
        if f.is_padding or f.name not in batch.columns:
            continue
        typ = _raw_type(f.type)
        values = batch.columns[f.name]
        if pa.types.is_list(typ) or pa.types.is_fixed_size_list(typ):
            if values.dtype == object:
                arr = pa.array([list(v) for v in values], type=typ)
            else:
                flat = pa.array(values.reshape(-1), type=typ.value_type)
                width = values.shape[1] if values.ndim == 2 else 0
                arr = pa.FixedSizeListArray.from_arrays(flat, width).cast(typ)
        elif pa.types.is_string(typ):
            arr = pa.array(
                [v.split(b"\0", 1)[0].decode("utf-8", "replace") if isinstance(v, bytes) else v for v in values], typ
            )
        else:
            arr = pa.array(values, type=typ, from_pandas=False)
        meta = {"unit": f.unit.symbol} if f.unit is not None else {}
        if f.invalid is not None:
            meta["invalid"] = f.invalid.text
        fields.append(pa.field(f.name, typ, metadata=meta or None))
        arrays.append(arr)
    return pa.Table.from_arrays(
        arrays, schema=pa.schema(fields, metadata={"battgen": json.dumps({"message": message.qualified_name})})
    )


def _write(table: Any, path: Path) -> None:
    """zstd, with dictionary encoding only for the text columns: trying it on every float column
    costs most of the write time and saves nothing on measured values."""
    text = [f.name for f in table.schema if pa.types.is_string(f.type)]
    pq.write_table(table, path, compression="zstd", use_dictionary=text)


def write_log(
    out: Path,
    log: str,
    battery: Any,
    raws: Sequence[tuple[str, Any]],
    manifest: dict[str, object],
    tables: Sequence[tuple[str, dict[str, Any]]] = (),
    partition: str | None = None,
) -> None:
    """Write one log's partitions and then its marker (see the module docstring). ``tables``: more
    tables of the log, (table folder, {file name: table}) (the failsafe replay's); ``partition``: the
    log's folder under each table (:func:`partition_of`; default ``log=<id>``)."""
    where = partition or f"log={log}"
    out.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".tmp-{log}-", dir=out))
    try:
        moves: list[tuple[Path, Path]] = []
        part = tmp / BATTERY
        part.mkdir()
        _write(battery, part / "part-0.parquet")
        moves.append((part, out / BATTERY / where))
        for i, (message, table) in enumerate(raws):
            rpart = tmp / f"{RAW}-{i}"
            rpart.mkdir()
            _write(table, rpart / "part-0.parquet")
            moves.append((rpart, out / RAW / message / where))
        for i, (folder, files) in enumerate(tables):
            tpart = tmp / f"table-{i}"
            tpart.mkdir()
            for file_name, table in files.items():
                _write(table, tpart / file_name)
            moves.append((tpart, out / folder / where))
        for src, dst in moves:
            dst.parent.mkdir(parents=True, exist_ok=True)
            if dst.exists():  # an earlier run stopped before its marker: its partition is replaced
                shutil.rmtree(dst)
            os.replace(src, dst)
        mark = marker(out, log)
        mark.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
        tmp_mark = tmp / "marker.json"
        tmp_mark.write_text(text, encoding="utf-8")
        os.replace(tmp_mark, mark)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
