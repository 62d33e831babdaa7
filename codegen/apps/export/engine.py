"""The per-log export and the runs over many logs: in this process, in ``jobs`` processes, or as
tasks on a Dask cluster (:mod:`.distributed`), all through :func:`export_one`.

A log is identified by its content (:func:`.sources.content_id`): one already in the dataset is
skipped, so a nightly run over a growing fleet does only the new logs. A log that cannot be read
is reported in its :class:`LogResult` and the run goes on.
"""

from __future__ import annotations

import dataclasses
import datetime
import functools
import mmap
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import BattgenError, OutputError, cannot_read
from ...inputs.files.held import held
from ..battery.catalog import bundled_catalog
from ..battery.sources import Batch, log_kind
from ..battery.view import read_view
from .content import content_id, map_file, prefix_id
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
from .manifest import EVENTS_FILE, FAILSAFE, REPLAYS_FILE, exported_sources, retire, sweep
from .table import battery_schema, battery_table
from .views import write_views

if TYPE_CHECKING:  # what only some runs need is imported where they need it: a fresh process pays for its run only
    from ..failsafe.logs import SampleTable
    from .failsafe_tables import FailsafeOptions


@dataclass(frozen=True)
class ExportOptions:
    """What every per-log export of a run shares (picklable: it travels to worker processes)."""

    out: Path
    raw: bool = False
    message: str | None = None  # the message of JSON Lines inputs (None: told from their keys)
    failsafe: FailsafeOptions | None = None  # --failsafe: replay each log through the battery failsafe
    partition: str = "log"  # "log" or "day" (see .dataset)
    content_id: str | None = None  # the hash naming logs (None: the dataset's, .dataset.content_scheme)
    earlier: tuple[tuple[str, str, int], ...] = ()  # (source, log, bytes) of the logs in the dataset at the start
    cyphal_subjects: tuple[str, ...] = ()  # --cyphal-subject ID=TYPE: the Cyphal types of a CAN capture's subjects


@dataclass(frozen=True)
class LogResult:
    """What became of one input: ``exported``, ``skipped`` (already in the dataset, or the same
    content as another input) or ``failed`` (``error`` says why)."""

    path: str
    status: str
    log: str = ""
    rows: int = 0
    error: str = ""
    replaced: str = ""  # the log this one replaces: an earlier export of the same file, shorter then
    notes: tuple[str, ...] = field(default=())
    warnings: tuple[str, ...] = field(default=())  # records the export left out, each said once (also in notes)


def export_one(path: str, options: ExportOptions) -> LogResult:
    """Export one log into the dataset at ``options.out``; never raises for a bad log."""
    file = Path(path)
    try:
        with held(file, path) as hold:
            return _export_held(file, path, options, map_file(file, hold.leased))
    except OutputError:
        raise  # the dataset cannot be written: the run stops (the CLI says where, in one line)
    except BattgenError as exc:  # the file changed while it was read (FileChanged): nothing of it was kept
        return LogResult(path, "failed", error=str(exc))


def _export_held(file: Path, path: str, options: ExportOptions, source: mmap.mmap | bytes | None) -> LogResult:
    """:func:`export_one` of a file held still; ``source``: a ULog is hashed and read through one memory map."""
    try:
        try:
            log = content_id(file, source, options.content_id or content_scheme(options.out))
        except OSError as exc:
            return LogResult(path, "failed", error=f"{path}: {cannot_read(exc)}")
        if is_exported(options.out, log) and not _replay_missing(options, log):
            return LogResult(path, "skipped", log, notes=("already in the dataset",))
        try:
            return _export(file, path, log, options, source, _grown_from(file, source, options))
        except OutputError:
            raise
        except BattgenError as exc:
            return LogResult(path, "failed", log, error=str(exc))
        except (OSError, ValueError, MemoryError) as exc:  # a log the readers did not foresee
            if isinstance(exc, OSError) and is_exported(options.out, log):  # the same content, exported meanwhile
                return LogResult(path, "skipped", log, notes=("the same content was exported by another task",))
            return LogResult(path, "failed", log, error=f"{path}: cannot export: {type(exc).__name__}: {exc}")
    finally:
        if isinstance(source, mmap.mmap) and not source.closed:
            source.close()


def _grown_from(file: Path, source: mmap.mmap | bytes | None, options: ExportOptions) -> str | None:
    """The log this file grew from: an earlier export of a file of the same name whose content is this one's
    start (a tlog downloaded again with more frames). Its id is the hash of those bytes, so a match is that
    content, not a name alone."""
    try:
        size = file.stat().st_size
    except OSError:
        return None
    scheme = options.content_id or content_scheme(options.out)
    for name, log, earlier_size in options.earlier:
        if name == file.name and 0 < earlier_size < size and prefix_id(file, earlier_size, source, scheme) == log:
            return log
    return None


def _replay_missing(options: ExportOptions, log: str) -> bool:
    """A log exported before without this run's failsafe replay is exported again (with it)."""
    if options.failsafe is None:
        return False
    manifest = exported_manifest(options.out, log)
    return manifest is None or manifest.get("failsafe") != options.failsafe.key


def _export(
    file: Path, name: str, log: str, options: ExportOptions, source: mmap.mmap | bytes | None, grown: str | None
) -> LogResult:
    """The batches stream through: each converted, its rows written, and let go (a log of any length
    in flat memory); the failsafe replay keeps what it needs of each (its context, not its columns)."""
    size = len(source) if source is not None else file.stat().st_size  # before the reader closes the map
    catalog = bundled_catalog()
    schema = battery_schema(catalog)
    kind = log_kind(file)
    writer = LogWriter(options.out, log, schema)
    notes: list[str] = []
    warnings: list[str] = []
    messages: set[str] = set()
    replay = None if options.failsafe is None else _sample_table()  # what the replay needs of each chunk
    clock: Batch | None = None  # a batch of the log, for the replay's time of day
    first_us: int | None = None  # the log's first time of day (UTC µs), which names its day partition (--partition day)
    try:
        for chunk in read_view(
            file,
            name,
            catalog=catalog,
            message=options.message,
            source=source,
            all_fields=options.raw,
            subjects=options.cyphal_subjects,
        ):
            batch, columns = chunk.batch, chunk.concepts
            table = battery_table(catalog, schema, columns, batch, log, file.name)
            writer.add(table)
            # a Cyphal capture's types are written by cyphal_raw_tables below, each subject's every transfer
            if options.raw and batch.message in catalog.sources and not (kind == "can" and _cyphal(batch.message)):
                writer.add_raw(
                    batch.message, raw_table(catalog.schema.message(batch.message), batch, log, catalog.schema)
                )
            messages.add(batch.message)
            notes.extend(n for n in batch.notes if n not in notes)
            warnings.extend(batch.warnings)
            if options.partition == "day":  # only a day partition needs it
                first = _first_time(batch)
                if first is not None:
                    first_us = first if first_us is None else min(first_us, first)
            if replay is not None:
                replay.add(chunk)
                clock = clock or (batch if batch.n else None)
        if options.raw and kind == "dataflash":
            from .dataflash_raw import dataflash_raw_tables

            for message, raw in dataflash_raw_tables(file, name, log):
                writer.add_raw(message, raw)
        if options.raw and kind == "can" and options.cyphal_subjects:  # every subject's type, not only SourceTs
            from ..schemas.package import bundled_package
            from .cyphal_raw import cyphal_raw_tables

            package = bundled_package().__name__
            for message, raw in cyphal_raw_tables(file, name, log, options.cyphal_subjects, catalog.schema, package):
                writer.add_raw(message, raw)
    except BaseException:
        writer.abort()
        raise
    if not writer.rows:
        notes.append("no battery records")
    extra: list[tuple[str, dict[str, Any]]] = []
    if options.failsafe is not None:
        from .failsafe_tables import replay_tables

        assert replay is not None
        try:
            replayed = replay_tables(file, name, kind, log, options.failsafe, replay, clock)
        except BattgenError as exc:
            replayed = f"failsafe not replayed: {exc}"
        if isinstance(replayed, str):
            notes.append(replayed)
        else:
            extra.append((FAILSAFE, {EVENTS_FILE: replayed[0], REPLAYS_FILE: replayed[1]}))
    if grown is not None:
        notes.append(f"replaces log {grown}: an earlier export of {file.name}, which this file continues")
    manifest: dict[str, object] = {
        "log": log,
        "source": file.name,
        "bytes": size,
        "rows": writer.rows,
        "messages": sorted(messages),
        "notes": notes + warnings,
    }
    if options.failsafe is not None:
        manifest["failsafe"] = options.failsafe.key
    where = partition_of(options.partition, log, utc_day(first_us))
    manifest["partition"] = where
    manifest["content_id"] = options.content_id or content_scheme(
        options.out
    )  # the dataset's record again, should dataset.json lose its key
    if grown is not None:
        manifest["replaces"] = grown  # the commit that shows this log hides the one it continues
    writer.commit(manifest, extra, where)
    if grown is not None:
        retire(options.out, grown)
    return LogResult(
        name,
        "exported",
        log,
        writer.rows,
        replaced=grown or "",
        notes=tuple(notes + warnings),
        warnings=tuple(warnings),
    )


def _sample_table() -> SampleTable:
    from ..failsafe.logs import SampleTable

    return SampleTable()


def _cyphal(message: str) -> bool:
    """Whether a CAN capture's batch is of a Cyphal type (written by :func:`.cyphal_raw.cyphal_raw_tables`)."""
    from .cyphal_raw import CYPHAL_PREFIX

    return message.startswith(CYPHAL_PREFIX)


def _first_time(batch: Batch) -> int | None:
    """The batch's earliest time of day (µs since the epoch), where it has one."""
    if batch.time_us is None or not batch.n:
        return None
    times = batch.time_us if batch.time_known is None else batch.time_us[batch.time_known]
    return int(np.min(times)) if len(times) else None


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
    scheme = claim_layout(options.out, options.partition, options.content_id)
    return dataclasses.replace(options, content_id=scheme, earlier=exported_sources(options.out))


def _run(paths: list[str], options: ExportOptions, jobs: int) -> Iterator[LogResult]:
    if jobs <= 1 or len(paths) <= 1:
        for p in paths:
            yield export_one(p, options)
        return
    from .workers import run_pooled

    yield from run_pooled(functools.partial(export_one, options=options), paths, jobs, _died)


def _died(path: str, why: str) -> LogResult:
    return LogResult(path, "failed", error=f"{path}: {why}")


def count(results: Iterable[LogResult], status: str) -> int:
    return sum(1 for r in results if r.status == status)


def finish(out: Path, on_wait: Callable[[str], None] | None = None) -> None:
    """After a run: the views file in the dataset folder (under the writers' lock: the committed logs
    of that moment)."""
    with writers_lock(out, on_wait):
        write_views(out)
