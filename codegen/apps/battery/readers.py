"""The batches of one log of any kind the export reads: DataFlash through
:mod:`.dataflash_batches`, CAN captures through :mod:`.can_batches`, tlogs through :mod:`.tlog_batches`,
the others through :mod:`.sources`."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

from ...inputs.files.held import Buffer, held, whole
from .catalog import Catalog
from .sources import Batch, jsonl_batches, log_kind, model_of, ulog_batches


def read_batches(path: Path, name: str, catalog: Catalog, message: str | None = None) -> list[Batch]:
    """Every battery batch of one log, every field of ULog records (see :func:`read_log`)."""
    return list(read_log(path, name, catalog, message))


def read_log(
    path: Path,
    name: str,
    catalog: Catalog,
    message: str | None = None,
    source: Buffer | None = None,
    all_fields: bool = True,
    subjects: Sequence[str] = (),
) -> Iterator[Batch]:
    """The battery batches of one log, one at a time (a ULog's in chunks: memory stays flat). Raises
    InputError (or another BattgenError) if unreadable. ``source``: a memory map of a ULog file the
    caller holds (the log closes it); without ``all_fields`` a ULog batch holds only the fields the
    mapping reads (and the timestamp); ``message``: that of JSON Lines records (None: told from
    their keys); ``subjects``: the ``--cyphal-subject`` pairs a CAN capture is read with. The file is
    held still while it is read (:mod:`...inputs.held_file`): a program that rewrites it meanwhile
    makes this raise FileChanged, never a crash."""
    kind = log_kind(path)
    with held(path, name) as hold:
        if kind == "ulog":
            if source is None and not hold.leased:  # unheld, a map could end in SIGBUS: read it whole
                source = whole(path, name)
            yield from ulog_batches(path, name, catalog, source, all_fields)
        # each kind's reader is imported when a log of that kind is read: a fresh process exporting a ULog
        # does not load python-can (0.15-0.3 s) or pymavlink's readers
        elif kind == "tlog":
            from .tlog_batches import tlog_batches

            yield from tlog_batches(path, name, catalog)
        elif kind == "dataflash":
            from .dataflash_batches import dataflash_batches

            yield from dataflash_batches(path, name, catalog)
        elif kind == "can":
            from .can_batches import can_batches

            yield from can_batches(path, name, catalog, model_of, subjects)
        else:
            yield from jsonl_batches(path, name, catalog, message)
