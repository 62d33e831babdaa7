"""The battery view: every log of every kind as chunks of the shared battery concepts, with the log's context.

This is the one reading of a battery log that ``export``, ``report`` and ``failsafe`` share. A log is read once by
the source of its kind (:func:`.readers.read_log`: ULog columns through the C walk, tlog frames, DataFlash records,
CAN transfers, JSON Lines records) into :class:`~.sources.Batch`\\ es, and each batch becomes concepts through the
IR's mappings applied to whole columns (:func:`.columnar.convert_columns`), or the source's own concepts where the
format has no message schema (DataFlash). What the concepts mean is the IR's: a field's sentinel is unknown, and
nothing else is (a negative current is a charging battery, not an unknown one).

The context, stated once per batch (:class:`~.sources.Batch`): ``t`` is seconds since the log's start for every
kind; ``armed`` is the vehicle's arming state as of each record, by one rule per kind (see the source), NaN before
the log says anything, and ``None`` for a log that carries no arming state at all (a CAN capture, a JSON Lines
file); the battery of a record is its message's own battery index where the message has one, else the source's
instance (:func:`battery_of`).
"""

from __future__ import annotations

import functools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...inputs.files.held import Buffer
from .catalog import Catalog, bundled_catalog
from .columnar import convert_columns
from .columns import ConceptColumn, NDArray
from .readers import read_log
from .sources import Batch


@dataclass
class Chunk:
    """One batch of a log and its concepts."""

    batch: Batch
    concepts: dict[str, ConceptColumn]

    @property
    def n(self) -> int:
        return self.batch.n

    @functools.cached_property
    def battery(self) -> NDArray:  # the report and the failsafe's table both ask for it
        return battery_of(self.concepts, self.batch)

    def number(self, concept: str) -> NDArray:
        """A number concept as float64, NaN where it is unknown."""
        return known(self.concepts[concept])


def battery_of(concepts: Mapping[str, ConceptColumn], batch: Batch) -> NDArray:
    """The battery (0-based) of each record: the message's battery index where it gives one (uORB ``id``, MAVLink
    ``id``, DroneCAN ``battery_id``), else the source's instance (ULog ``multi_id``, DataFlash ``Inst``)."""
    index = concepts["battery_index"]
    return np.asarray(np.where(index.valid, index.values, batch.instance), np.int32)


def known(column: ConceptColumn) -> NDArray:
    """A number concept's values as float64, NaN where unknown."""
    return np.where(column.valid, np.asarray(column.values, np.float64), np.nan)


def read_view(
    path: Path,
    name: str | None = None,
    *,
    catalog: Catalog | None = None,
    message: str | None = None,
    source: Buffer | None = None,
    all_fields: bool = False,
    subjects: Sequence[str] = (),
) -> Iterator[Chunk]:
    """The chunks of one log, in the order its source reads them (a ULog topic instance in chunks of records;
    memory stays flat). Raises InputError (or another BattgenError) for a log that cannot be read. ``message``:
    that of JSON Lines records (None: told from their keys); ``source``: a memory map of a ULog the caller holds;
    ``all_fields``: every field of ULog records in the batch, not only those the mapping reads; ``subjects``: the
    ``--cyphal-subject`` pairs (``ID=TYPE``) a CAN capture's Cyphal subjects are read with."""
    catalog = catalog or bundled_catalog()
    for batch in read_log(path, name or path.as_posix(), catalog, message, source, all_fields, subjects):
        concepts = batch.concepts
        if concepts is None:
            concepts = convert_columns(catalog, catalog.source(batch.message), batch.columns, batch.n)
        yield Chunk(batch, concepts)
