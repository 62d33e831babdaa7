"""The per-log export and the runs over many logs: in this process, in ``jobs`` processes, or as
tasks on a Dask cluster (:mod:`.distributed`), all through :func:`export_one`.

A log is identified by its content (:func:`.sources.content_id`): one already in the dataset is
skipped, so a nightly run over a growing fleet does only the new logs. A log that cannot be read
is reported in its :class:`LogResult` and the run goes on.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import datetime
import mmap
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc

from ...errors import BattgenError, cannot_read
from ..battery.catalog import bundled_catalog
from ..battery.sources import Batch, log_kind
from ..battery.view import read_view
from ..failsafe.logs import SampleTable
from .content import content_id, map_file
from .dataflash_raw import dataflash_raw_tables
from .dataset import (
    LogWriter,
    claim_layout,
    content_scheme,
    exported_manifest,
    is_exported,
    partition_of,
    raw_table,
)
from .durable import writers_lock
from .failsafe_tables import EVENTS_FILE, FAILSAFE, REPLAYS_FILE, FailsafeOptions, replay_tables
from .manifest import sweep
from .table import battery_schema, battery_table
from .views import write_views


@dataclass(frozen=True)
class ExportOptions:
    """What every per-log export of a run shares (picklable: it travels to worker processes)."""

    out: Path
    raw: bool = False
    message: str | None = None  # the message of JSON Lines inputs (None: told from their keys)
    failsafe: FailsafeOptions | None = None  # --failsafe: replay each log through the battery failsafe
    partition: str = "log"  # "log" or "day" (see .dataset)
    content_id: str | None = None  # the hash naming logs (None: the dataset's, .dataset.content_scheme)


@dataclass(frozen=True)
class LogResult:
    """What became of one input: ``exported``, ``skipped`` (already in the dataset, or the same
    content as another input) or ``failed`` (``error`` says why)."""

    path: str
    status: str
    log: str = ""
    rows: int = 0
    error: str = ""
    notes: tuple[str, ...] = field(default=())


def export_one(path: str, options: ExportOptions) -> LogResult:
    """Export one log into the dataset at ``options.out``; never raises for a bad log."""
    file = Path(path)
    source = map_file(file)  # a ULog is hashed and read through one memory map
    try:
        try:
            log = content_id(file, source, options.content_id or content_scheme(options.out))
        except OSError as exc:
            return LogResult(path, "failed", error=f"{path}: {cannot_read(exc)}")
        if is_exported(options.out, log) and not _replay_missing(options, log):
            return LogResult(path, "skipped", log, notes=("already in the dataset",))
        try:
            return _export(file, path, log, options, source)
        except BattgenError as exc:
            return LogResult(path, "failed", log, error=str(exc))
        except (OSError, ValueError, MemoryError) as exc:  # a log the readers did not foresee
            if isinstance(exc, OSError) and is_exported(options.out, log):  # the same content, exported meanwhile
                return LogResult(path, "skipped", log, notes=("the same content was exported by another task",))
            return LogResult(path, "failed", log, error=f"{path}: cannot export: {type(exc).__name__}: {exc}")
    finally:
        if source is not None and not source.closed:
            source.close()


def _replay_missing(options: ExportOptions, log: str) -> bool:
    """A log exported before without this run's failsafe replay is exported again (with it)."""
    if options.failsafe is None:
        return False
    manifest = exported_manifest(options.out, log)
    return manifest is None or manifest.get("failsafe") != options.failsafe.key


def _export(file: Path, name: str, log: str, options: ExportOptions, source: mmap.mmap | None) -> LogResult:
    """The batches stream through: each converted, its rows written, and let go (a log of any length
    in flat memory); the failsafe replay keeps what it needs of each (its context, not its columns)."""
    catalog = bundled_catalog()
    schema = battery_schema(catalog)
    kind = log_kind(file)
    writer = LogWriter(options.out, log, schema)
    notes: list[str] = []
    messages: set[str] = set()
    replay = SampleTable()  # what the failsafe replay needs of each chunk (not its columns)
    clock: Batch | None = None  # a batch of the log, for the replay's time of day
    first_us: int | None = None  # the log's first time of day (UTC µs), which names its day partition (--partition day)
    try:
        for chunk in read_view(
            file, name, catalog=catalog, message=options.message, source=source, all_fields=options.raw
        ):
            batch, columns = chunk.batch, chunk.concepts
            table = battery_table(catalog, schema, columns, batch, log, file.name)
            writer.add(table)
            if options.raw and batch.message in catalog.sources:
                writer.add_raw(batch.message, raw_table(catalog.schema.message(batch.message), batch, log))
            messages.add(batch.message)
            notes.extend(n for n in batch.notes if n not in notes)
            if options.partition == "day" and table.num_rows:  # only a day partition needs it
                first = pc.min(table["time"].cast(pa.int64())).as_py()
                if first is not None:
                    first_us = first if first_us is None else min(first_us, first)
            if options.failsafe is not None:
                replay.add(chunk)
                clock = clock or (batch if batch.n else None)
        if options.raw and kind == "dataflash":
            for message, raw in dataflash_raw_tables(file, name, log):
                writer.add_raw(message, raw)
    except BaseException:
        writer.abort()
        raise
    if not writer.rows:
        notes.append("no battery records")
    extra: list[tuple[str, dict[str, Any]]] = []
    if options.failsafe is not None:
        try:
            replayed = replay_tables(file, name, kind, log, options.failsafe, replay, clock)
        except BattgenError as exc:
            replayed = f"failsafe not replayed: {exc}"
        if isinstance(replayed, str):
            notes.append(replayed)
        else:
            extra.append((FAILSAFE, {EVENTS_FILE: replayed[0], REPLAYS_FILE: replayed[1]}))
    manifest: dict[str, object] = {
        "log": log,
        "source": file.name,
        "rows": writer.rows,
        "messages": sorted(messages),
        "notes": notes,
    }
    if options.failsafe is not None:
        manifest["failsafe"] = options.failsafe.key
    where = partition_of(options.partition, log, utc_day(first_us))
    manifest["partition"] = where
    writer.commit(manifest, extra, where)
    return LogResult(name, "exported", log, writer.rows, notes=tuple(notes))


def utc_day(us: int | None) -> str | None:
    """The UTC day (YYYY-MM-DD) of a time in µs since the epoch; None for none, or a time no
    calendar holds (a damaged log's clock)."""
    if us is None:
        return None
    try:
        return (datetime.datetime(1970, 1, 1) + datetime.timedelta(microseconds=us)).date().isoformat()
    except OverflowError:
        return None


def export_logs(
    paths: Sequence[str],
    options: ExportOptions,
    *,
    jobs: int = 1,
    progress: Callable[[LogResult], None] | None = None,
    on_wait: Callable[[str], None] | None = None,
) -> list[LogResult]:
    """Export every log, in input order of the results; ``jobs`` > 1 runs them in processes. The run
    holds the dataset's writers' lock (``on_wait`` is told when another export holds it) and starts by
    removing what a stopped run left (:func:`.manifest.sweep`)."""
    with writers_lock(options.out, on_wait):
        options = start(options)
        unique = list(dict.fromkeys(paths))
        results: dict[str, LogResult] = {}
        for res in _run(unique, options, jobs):
            results[res.path] = res
            if progress is not None:
                progress(res)
        return [results[p] for p in unique]


def start(options: ExportOptions) -> ExportOptions:
    """The start of a run, under the writers' lock: leftovers of a stopped run removed, the layout
    claimed (:func:`.dataset.claim_layout`); the options with the dataset's content id."""
    sweep(options.out)
    return dataclasses.replace(options, content_id=claim_layout(options.out, options.partition, options.content_id))


def _run(paths: list[str], options: ExportOptions, jobs: int) -> Iterator[LogResult]:
    if jobs <= 1 or len(paths) <= 1:
        for p in paths:
            yield export_one(p, options)
        return
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(export_one, p, options) for p in paths]
        for fut in concurrent.futures.as_completed(futures):
            yield fut.result()


def count(results: Iterable[LogResult], status: str) -> int:
    return sum(1 for r in results if r.status == status)


def finish(out: Path, on_wait: Callable[[str], None] | None = None) -> None:
    """After a run: the views file in the dataset folder (under the writers' lock: the committed logs
    of that moment)."""
    with writers_lock(out, on_wait):
        write_views(out)
