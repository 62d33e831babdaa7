"""CAN bus captures (candump .log, Vector .asc/.blf, PEAK .trc, each also .gz) for the export: the
battery nodes' DroneCAN messages, one batch per node and message.

Read through the capture readers of :mod:`codegen.inputs.can` (frames reassembled into transfers,
CRCs checked, each transfer decoded by its generated class), twice: once for ``BatteryInfo``, each
paired with its node's latest ``BatteryInfoAux`` as PX4's DroneCAN bridge pairs them, and once for
CUAV's ``CBAT``. Both go through the IR mappings with the columnar converter; the aux message's
concepts (cell voltages, cycle count, ...) fill what BatteryInfo leaves unknown, as the mapping's
rule order has it (BatteryInfo's ``battery_id`` wins over the aux one's).

``t`` is the capture's time since its first frame, ``time`` the time of day where the capture's
stamps are absolute (candump, BLF, TRC); a capture says nothing of the vehicle. The
battery is the message's ``battery_id``; where two nodes report the same id (common: many smart
batteries ship with id 0), every battery of the capture is numbered by its node id instead, and the
log's notes say so. Transport damage (bad CRCs, lost frames) is counted in the notes; a capture
without any CAN frame is unreadable.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import cast

import numpy as np

from ...inputs.can.captures import capture_start
from ...inputs.can.records import capture_side
from ...inputs.model import MessageClass
from ...inputs.records import InputError, Notice, Record, Unreadable
from .catalog import Catalog
from .columnar import convert_columns
from .columns import ConceptColumn, NDArray
from .sources import Batch, instances_to_columns

INFO = "dronecan.uavcan.equipment.power.BatteryInfo"
AUX = "dronecan.ardupilot.equipment.power.BatteryInfoAux"
CBAT = "dronecan.cuav.equipment.power.CBAT"
MESSAGES = ((INFO, AUX), (CBAT,))  # each read with its companions
ModelOf = Callable[[Catalog, str], MessageClass]


def can_batches(path: Path, name: str, catalog: Catalog, model_of: ModelOf) -> list[Batch]:
    """Every battery node's batches of a capture; raises InputError if the capture is unreadable."""
    out: list[Batch] = []
    notes: list[str] = []
    for qualified in MESSAGES:
        models = [model_of(catalog, q) for q in qualified]
        by_node: dict[int, list[Record]] = {}
        damaged: list[str] = []
        for item in capture_side(path, name, models):
            if isinstance(item, Record):
                node = int(cast(int, (item.location or {}).get("node", 0)))
                by_node.setdefault(node, []).append(item)
            elif isinstance(item, Unreadable):
                damaged.append(item.message)
            elif isinstance(item, Notice):
                if item.kind == "empty" and item.severity == "error":
                    raise InputError(name, 0, item.message)
                if item.kind == "transport" and item.severity == "error" and qualified[0] == INFO:
                    damaged.append(item.message)
        if damaged:
            notes.append(f"{len(damaged)} damaged or undecodable transfers skipped (first: {damaged[0]})")
        for node, records in sorted(by_node.items()):
            out.append(_batch(catalog, qualified, node, records))
    _number_batteries(out, notes)
    start = capture_start(path, name) if out else None
    if start is not None:  # absolute stamps: the time of day of each record
        origin = round(start * 1e6)
        for b in out:
            b.utc_offset_us = origin
            b.time_us = np.round(b.t * 1e6).astype(np.int64) + origin
    if out:
        out[0].notes.extend(notes)
    return out


def _batch(catalog: Catalog, qualified: Sequence[str], node: int, records: list[Record]) -> Batch:
    n = len(records)
    main = qualified[0]
    instances = [r.instance for r in records]
    columns = instances_to_columns(catalog.schema.message(main), instances)
    t = np.array([float(cast(float, (r.location or {}).get("t", np.nan))) for r in records])
    batch = Batch(main, n, columns, t, np.full(n, node))
    concepts = convert_columns(catalog, catalog.source(main), columns, n)
    for position, companion in enumerate(qualified[1:]):
        rows = np.array([r.companions[position] is not None for r in records], bool)
        if not rows.any():
            continue
        seen = [m for m in (r.companions[position] for r in records) if m is not None]
        aux_columns = instances_to_columns(catalog.schema.message(companion), seen)
        aux = convert_columns(catalog, catalog.companions[companion], aux_columns, len(seen))
        for concept, column in aux.items():
            _fill(concepts[concept], column, rows)
    batch.concepts = concepts
    return batch


def _fill(target: ConceptColumn, source: ConceptColumn, rows: NDArray) -> None:
    """Where ``target`` is unknown and the companion (known at ``rows``) says: take the companion's."""
    if not source.valid.any():
        return
    where = np.zeros(len(rows), bool)
    where[rows] = source.valid
    where &= ~target.valid
    if not where.any():
        return
    if target.concept.kind == "list":
        assert source.lengths is not None
        values = np.full((len(rows), source.values.shape[1]), np.nan)
        values[rows] = source.values
        lengths = np.zeros(len(rows), np.int64)
        lengths[rows] = source.lengths
        target.set_list(values, lengths, where)
        return
    values = np.zeros(len(rows), source.values.dtype) if source.values.dtype != object else np.full(len(rows), None)
    values[rows] = source.values
    target.set(values, where)


def _number_batteries(batches: list[Batch], notes: list[str]) -> None:
    """battery_id as the battery, unless two nodes share one: then the node id for all."""
    ids: dict[int, set[int]] = {}
    for b in batches:
        assert b.concepts is not None
        index = b.concepts["battery_index"]
        node = int(b.instance[0])
        ids.setdefault(node, set()).update(int(v) for v in index.values[index.valid])
    owners: dict[int, set[int]] = {}
    for node, found in ids.items():
        for battery in found:
            owners.setdefault(battery, set()).add(node)
    shared = sorted(b for b, nodes in owners.items() if len(nodes) > 1)
    if not shared:
        return
    for b in batches:
        assert b.concepts is not None
        b.concepts["battery_index"].set(np.asarray(b.instance, np.int64))
    notes.append(
        f"nodes {', '.join(map(str, sorted(ids)))} share battery_id {shared[0]}: batteries numbered by node id"
    )
