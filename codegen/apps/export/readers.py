"""The batches of one log of any kind the export reads: DataFlash through
:mod:`.dataflash_batches`, CAN captures through :mod:`.can_batches`, the others through :mod:`.sources`."""

from __future__ import annotations

from pathlib import Path

from .can_batches import can_batches
from .catalog import Catalog
from .dataflash_batches import dataflash_batches
from .sources import Batch, export_kind, model_of, read_batches


def read_log(path: Path, name: str, catalog: Catalog, message: str | None = None) -> list[Batch]:
    """Every battery batch of one log. Raises InputError (or another BattgenError) if unreadable."""
    kind = export_kind(path)
    if kind == "dataflash":
        return dataflash_batches(path, name, catalog)
    if kind == "can":
        return can_batches(path, name, catalog, model_of)
    return read_batches(path, name, catalog, message)
