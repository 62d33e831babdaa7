"""The batches of one log of any kind the export reads: DataFlash through
:mod:`.dataflash_batches`, CAN captures through :mod:`.can_batches`, the others through :mod:`.sources`."""

from __future__ import annotations

import mmap
from collections.abc import Iterator
from pathlib import Path

from .can_batches import can_batches
from .catalog import Catalog
from .dataflash_batches import dataflash_batches
from .sources import Batch, export_kind, iter_batches, model_of


def read_log(
    path: Path,
    name: str,
    catalog: Catalog,
    message: str | None = None,
    source: mmap.mmap | None = None,
    all_fields: bool = True,
) -> Iterator[Batch]:
    """The battery batches of one log, one at a time. Raises InputError (or another BattgenError)
    if unreadable; ``source`` and ``all_fields``: see iter_batches."""
    kind = export_kind(path)
    if kind == "dataflash":
        yield from dataflash_batches(path, name, catalog)
    elif kind == "can":
        yield from can_batches(path, name, catalog, model_of)
    else:
        yield from iter_batches(path, name, catalog, message, source, all_fields)
