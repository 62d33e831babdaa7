"""The dataset folder: Hive-style partitions by log, written so a crash leaves no half log.

Layout under the output folder::

    battery/log=<id>/part-<version>.parquet        the normalised table (one file per log)
    raw/<message>/log=<id>/part-<version>.parquet  --raw: every field as decoded, sentinels kept
    failsafe/log=<id>/events-<version>.parquet     --failsafe: the replay's events (and replays-<version>)
    logs/<id>.json                                 the log's marker: what was exported, the files of its version
    views.sql                                      the DuckDB views (see codegen.apps.export.query)
    dataset.json                                   {"partition": "log" or "day", "content_id": "xxh128" or "sha256"}
    .battgen-export.lock                           the writers' lock (one export at a time)

``--partition day`` puts a ``day=YYYY-MM-DD`` level (UTC, from the log's first record with a time
of day; Hive's ``__HIVE_DEFAULT_PARTITION__``, read as null, where the log has none) above each
``log=<id>`` folder.

A log's files are written into a temporary folder beside them, fsynced, moved into place under a new
version's names, and made visible by one rename, its marker's (:mod:`.manifest`): a log whose marker
exists is complete, and ``battgen export`` skips it when it meets the same content again. A re-export
(``--failsafe`` with other parameters) writes its version beside the old one and removes the old files
after the marker names the new ones. ``dataset.json`` is written the same way, and an unreadable one is
refused, never replaced by defaults (the layout and log ids of every later run depend on it).
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import secrets
import shutil
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ...errors import BattgenError, OutputError
from ...ir import ArrayType, CompositeType, Field, Message, PrimitiveKind, PrimitiveType, Schema, StringType
from ..battery.columns import length_key
from ..battery.sources import Batch
from . import arrow
from .durable import TMP_PREFIX, fsync_dir, fsync_file, write_atomic
from .manifest import BATTERY, LOGS, RAW, marker, marker_files, read_marker
from .table import floats, repeated

__all__ = ["BATTERY", "LOGS", "RAW", "marker"]  # the layout's names, defined with the markers
ROW_GROUP = 1 << 18  # rows per Parquet row group (fewer, larger groups write faster; engines split them)
LAYOUT_FILE = "dataset.json"
PARTITIONS = ("log", "day")
CONTENT_IDS = ("xxh128", "sha256")  # the hashes naming logs; the first for new datasets
UNKNOWN_DAY = "__HIVE_DEFAULT_PARTITION__"  # Hive's name for a null partition value; DuckDB and pyarrow read it so


def _settings(out: Path) -> dict[str, Any]:
    """What ``dataset.json`` records; empty for a dataset without one (new, or from before it existed). One
    that cannot be read or holds something else is refused: re-defaulting it would switch a ``day`` dataset
    to ``log`` (its logs vanish from the views) or rename every log (each exported again)."""
    path = out / LAYOUT_FILE
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as exc:
        raise BattgenError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        data = json.loads(text)
    except (ValueError, RecursionError):  # a crafted file nested beyond the parser
        data = None
    if (
        not isinstance(data, dict)
        or not set(data) <= {"partition", "content_id"}
        or data.get("partition") not in PARTITIONS
        or data.get("content_id", CONTENT_IDS[0]) not in CONTENT_IDS
    ):
        raise BattgenError(
            f"{path}: expected the dataset's layout as battgen export writes it, "
            f'{{"partition": "log" or "day", "content_id": "xxh128" or "sha256"}}, got {text[:80]!r}: '
            "restore it (a marker in logs/ names each log's partition) or export into a new folder"
        )
    return data


def layout(out: Path) -> str:
    """How the dataset at ``out`` is partitioned: ``log`` (``<table>/log=<id>/``) or ``day``
    (``<table>/day=YYYY-MM-DD/log=<id>/``); a dataset from before ``dataset.json`` existed is by log."""
    found = _settings(out).get("partition")
    if found is None:  # no dataset.json: the partition its markers name (a day dataset's file was lost)
        first = next(iter(sorted((out / LOGS).glob("*.json"))), None) if (out / LOGS).is_dir() else None
        manifest = read_marker(out, first.stem) if first is not None else None
        found = "day" if manifest is not None and str(manifest.get("partition", "")).startswith("day=") else "log"
    return str(found)


def content_scheme(out: Path) -> str:
    """The hash naming the logs of the dataset at ``out`` (:func:`.sources.content_id`): the one
    its ``dataset.json`` records; SHA-256 for one whose logs were named before that record
    existed (they keep their ids, so a nightly run still skips them); XXH3-128 for a new one."""
    found = _settings(out).get("content_id")
    if found in CONTENT_IDS:
        return str(found)
    if not _has_logs(out):
        return CONTENT_IDS[0]
    for path in sorted((out / LOGS).glob("*.json")):  # markers record it too (those written since they do)
        recorded = (read_marker(out, path.stem) or {}).get("content_id")
        if recorded in CONTENT_IDS:
            return str(recorded)
    return "sha256"


def _has_logs(out: Path) -> bool:
    return (out / LOGS).is_dir() and any((out / LOGS).glob("*.json"))


def claim_layout(out: Path, partition: str, scheme: str | None = None) -> str:
    """Record the partitioning and content id of a dataset; refuse another partitioning or hash for
    an existing dataset (two layouts in one folder would not read back as one table; two hashes would
    name a log twice). ``scheme``: the hash for a new dataset (None: XXH3-128). Returns the dataset's
    hash (:func:`content_scheme`)."""
    if partition not in PARTITIONS:
        raise BattgenError(f"expected a partitioning among {', '.join(PARTITIONS)}, got {partition!r}")
    if scheme is not None and scheme not in CONTENT_IDS:
        raise BattgenError(f"expected a content id among {', '.join(CONTENT_IDS)}, got {scheme!r}")
    existing = _has_logs(out)
    if existing and layout(out) != partition:
        raise BattgenError(
            f"{out}: the dataset is partitioned by {layout(out)}; give --partition {layout(out)} or a new folder"
        )
    found = content_scheme(out)
    if existing and scheme is not None and scheme != found:
        raise BattgenError(f"{out}: the dataset names its logs by {found}, not {scheme}; give a new folder")
    chosen = found if existing or scheme is None else scheme
    out.mkdir(parents=True, exist_ok=True)
    settings = {"partition": partition, "content_id": chosen}
    if _settings(out) != settings:  # written once, not on every run
        write_atomic(out / LAYOUT_FILE, json.dumps(settings) + "\n")
    return chosen


def partition_of(partition: str, log: str, day: str | None) -> str:
    """A log's partition folder under each table: ``log=<id>`` or ``day=<YYYY-MM-DD>/log=<id>``."""
    if partition == "day":
        return f"day={day or UNKNOWN_DAY}/log={log}"
    return f"log={log}"


def table_glob(out: Path, table: str, file_name: str = "*.parquet", *, relative: bool = False) -> str:
    """The files of a table in the dataset's layout; ``relative``: a path relative to ``out``."""
    depth = "*/*" if layout(out) == "day" else "*"
    return f"{'' if relative else out.as_posix() + '/'}{table}/{depth}/{file_name}"


def is_exported(out: Path, log: str) -> bool:
    return read_marker(out, log) is not None


def exported_manifest(out: Path, log: str) -> dict[str, Any] | None:
    """What the marker of an exported log records (None: not exported, or a marker unreadable)."""
    return read_marker(out, log)


def new_version() -> str:
    """A version of a log's files: its time and a random part, so two writers never share one."""
    return f"{time.time_ns():x}{secrets.token_hex(3)}"


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


def _raw_fields(message: Message, batch: Batch, schema: Schema | None) -> Iterator[tuple[str, Field]]:
    """The columns of a raw table, by name, with their fields: the message's own fields, but a composite one (a
    Cyphal ``uavcan.si`` Scalar) as the numbers inside it the mapping reads, by their dotted paths
    (``value.power.voltage.volt``)."""
    for f in message.fields:
        inner = f.type.element if isinstance(f.type, ArrayType) else f.type
        if not f.is_padding and f.name in batch.columns and not isinstance(inner, CompositeType):
            yield f.name, f
    if schema is not None:
        for key in sorted(k for k in batch.columns if "." in k and not k.endswith(length_key(""))):
            yield key, schema.field_at(message.qualified_name, key)


def raw_table(message: Message, batch: Batch, log: str, schema: Schema | None = None) -> Any:
    """One batch as its message's own table: every field as decoded (arrays as lists); ``schema``: the one the
    message is in, naming the fields inside its composite ones."""
    arrays = [
        repeated(log, batch.n),
        arrow.array(np.asarray(batch.instance, np.int32), pa.int32()),
        floats(batch.t),
    ]
    fields = [pa.field("log", pa.string()), pa.field("instance", pa.int32()), pa.field("t", pa.float64())]
    for name, f in _raw_fields(message, batch, schema):
        typ = _raw_type(f.type)
        values = batch.columns[name]
        if pa.types.is_list(typ) or pa.types.is_fixed_size_list(typ):
            if values.dtype == object:
                arr = pa.array([list(v) for v in values], type=typ)
            elif length_key(name) in batch.columns:  # a variable-length array: each row its own length, not padded
                lengths = np.asarray(batch.columns[length_key(name)], np.int64)
                keep = np.arange(values.shape[1])[None, :] < lengths[:, None]
                offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int32)
                flat = _numbers(values[keep], typ.value_type)
                arr = pa.ListArray.from_arrays(arrow.array(offsets, pa.int32()), flat).cast(typ)
            else:
                flat = _numbers(values.reshape(-1), typ.value_type)
                width = values.shape[1] if values.ndim == 2 else 0
                arr = pa.FixedSizeListArray.from_arrays(flat, width).cast(typ)
        elif pa.types.is_string(typ):
            arr = arrow.strings(
                [v.split(b"\0", 1)[0].decode("utf-8", "replace") if isinstance(v, bytes) else v for v in values]
            )
        else:
            arr = _numbers(values, typ)
        meta = {"unit": f.unit.symbol} if f.unit is not None else {}
        if f.invalid is not None:
            meta["invalid"] = f.invalid.text
        fields.append(pa.field(name, typ, metadata=meta or None))
        arrays.append(arr)
    return pa.Table.from_arrays(
        arrays, schema=pa.schema(fields, metadata={"battgen": json.dumps({"message": message.qualified_name})})
    )


def _numbers(values: Any, typ: Any) -> Any:
    """A column of numbers as Arrow (from its numpy buffer: ``pa.array`` would import pandas, see :mod:`.arrow`)."""
    if values.dtype == object:  # not one numpy type: what pa.array makes of Python numbers
        return pa.array(values, type=typ, from_pandas=False)
    return arrow.array(values, typ)


# The columns whose row-group statistics (min, max, nulls) are written: those a query over many logs
# filters on (vehicle, battery, when); the log, its file and message are its partition. Statistics of
# every column took a quarter of the Parquet write time on a million records.
STATISTICS = ("vehicle", "battery", "instance", "t", "time")


@functools.lru_cache(maxsize=64)
def _options(schema: Any) -> dict[str, Any]:
    """The Parquet writer's settings for ``schema``, each measured on a million records:

    - zstd;
    - text dictionary-encoded (a log, a file, a few choices);
    - integers and times delta-encoded: counts, indices and clocks change little from row to row
      (plain int64 under zstd was 4x slower to write than dictionaries; deltas with statistics on
      fewer columns, 10 % less write time than dictionaries with statistics on nine);
    - floats byte-stream-split, so the bytes of a kind compress together (3x smaller, 20 % faster
      to write); not dictionary-encoded (most of the write time, nothing saved on measured values);
    - data pages of format 2.0, which keep the levels out of the compressed data: the 35 or so
      concept columns a format never fills, all null, cost a third less;
    - statistics on :data:`STATISTICS` only.
    """
    dictionary: list[str] = []
    encodings: dict[str, str] = {}
    for f in schema:
        leaf = f.type.value_type if pa.types.is_list(f.type) or pa.types.is_fixed_size_list(f.type) else f.type
        if pa.types.is_floating(leaf):
            encodings[f.name] = "BYTE_STREAM_SPLIT"
        elif pa.types.is_integer(leaf) or pa.types.is_timestamp(leaf):
            encodings[f.name] = "DELTA_BINARY_PACKED"
        elif pa.types.is_string(leaf) or pa.types.is_dictionary(leaf):
            dictionary.append(f.name)
    return {
        "compression": "zstd",
        "use_dictionary": dictionary,
        "column_encoding": encodings or None,
        "data_page_version": "2.0",
        "write_statistics": [name for name in schema.names if name in STATISTICS],
    }


class LogWriter:
    """One log's partitions: tables appended as row groups (a log of any length in flat memory)
    into a temporary folder beside the dataset, moved into place by :meth:`commit`, its marker
    last (see the module docstring); :meth:`abort` leaves nothing behind."""

    def __init__(self, out: Path, log: str, schema: Any) -> None:
        self.out, self.log, self.schema = out, log, schema
        with self.writing():
            out.mkdir(parents=True, exist_ok=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{log}-", dir=out))
        self._writers: dict[str, Any] = {}  # "" for the battery table, else the raw table's message
        self._pending: dict[str, list[Any]] = {}  # tables not yet written, by writer key
        self.rows = 0

    def _writer(self, key: str, schema: Any) -> Any:
        writer = self._writers.get(key)
        if writer is None:
            folder = self.tmp / (BATTERY if not key else f"{RAW}-{len(self._writers)}")
            folder.mkdir()
            writer = self._writers[key] = pq.ParquetWriter(folder / "part-0.parquet", schema, **_options(schema))
        return writer

    @contextlib.contextmanager
    def writing(self) -> Iterator[None]:
        """The dataset's own failures (a full disk, a read-only folder) as OutputError: the run stops there,
        rather than count the log being written as unreadable and go on to fail the next."""
        try:
            yield
        except OSError as exc:
            raise OutputError.of(exc.filename or self.out, exc) from None

    def add(self, table: Any) -> None:
        """Rows of the battery table."""
        with self.writing():
            self._add("", table)
        self.rows += table.num_rows

    def add_raw(self, message: str, table: Any) -> None:
        """Rows of ``message``'s raw table (--raw)."""
        with self.writing():
            self._add(message, table)

    def _add(self, key: str, table: Any) -> None:
        """Tables are written in row groups of about ROW_GROUP rows: small ones cost per column."""
        pending = self._pending.setdefault(key, [])
        pending.append(table)
        if sum(t.num_rows for t in pending) >= ROW_GROUP:
            self._flush(key)

    def _flush(self, key: str) -> None:
        pending = self._pending.pop(key, [])
        if pending:
            self._writer(key, pending[0].schema).write_table(pa.concat_tables(pending), row_group_size=1 << 30)

    def commit(
        self,
        manifest: dict[str, object],
        tables: Sequence[tuple[str, dict[str, Any]]] = (),
        partition: str | None = None,
    ) -> None:
        """Close the files, move them into place under a new version's names and publish them by renaming
        the marker over the old one; then remove the old version's files (see the module docstring).
        ``tables``: more tables of the log, (table folder, {file name: table}) (the failsafe replay's);
        ``partition``: the log's folder under each table (:func:`partition_of`; default ``log=<id>``)."""
        where = partition or f"log={self.log}"
        version = new_version()
        with self.writing():
            self._commit(manifest, tables, where, version)

    def _commit(
        self, manifest: dict[str, object], tables: Sequence[tuple[str, dict[str, Any]]], where: str, version: str
    ) -> None:
        try:
            for key in list(self._pending):
                self._flush(key)
            self._writer("", self.schema)  # a log without battery records still gets its (empty) part
            folders = {key: Path(w.where).parent for key, w in self._writers.items()}
            for writer in self._writers.values():
                writer.close()
            self._writers.clear()
            # (file written in the temporary folder, its marker key, its place in the dataset)
            staged = [(folders.pop("") / "part-0.parquet", BATTERY, f"{BATTERY}/{where}/part-{version}.parquet")]
            staged += [
                (f / "part-0.parquet", RAW, f"{RAW}/{message}/{where}/part-{version}.parquet")
                for message, f in sorted(folders.items())
            ]
            for i, (table_folder, named) in enumerate(tables):
                part = self.tmp / f"table-{i}"
                part.mkdir()
                for file_name, table in named.items():
                    pq.write_table(table, part / file_name, **_options(table.schema))
                    stem = Path(file_name).stem
                    staged.append((part / file_name, stem, f"{table_folder}/{where}/{stem}-{version}.parquet"))
            for src, _, _ in staged:
                fsync_file(src)
            old = read_marker(self.out, self.log)
            for src, _, rel in staged:  # new names: nothing a reader reads is touched
                dst = self.out / rel
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.replace(src, dst)
            for parent in sorted({(self.out / rel).parent for _, _, rel in staged}):
                fsync_dir(parent)
            files: dict[str, list[str]] = {}
            for _, key, rel in staged:
                files.setdefault(key, []).append(rel)
            manifest = {**manifest, "version": version, "files": files}
            write_atomic(marker(self.out, self.log), json.dumps(manifest, indent=2, sort_keys=True) + "\n")
            if old is not None:  # the swap is done: the old version goes
                new = {rel for _, _, rel in staged}
                for names in marker_files(self.out, old).values():
                    for rel in names:
                        if rel not in new:
                            (self.out / rel).unlink(missing_ok=True)
        finally:
            self.abort()

    def abort(self) -> None:
        self._pending.clear()
        for writer in self._writers.values():
            writer.close()
        self._writers.clear()
        shutil.rmtree(self.tmp, ignore_errors=True)
