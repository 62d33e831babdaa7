"""CAN bus captures (candump .log, Vector .asc/.blf, PEAK .trc, each also .gz or .xz) for the export: the
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

from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import cast

import numpy as np

from ...inputs.can.captures import capture_start
from ...inputs.can.records import capture_side
from ...inputs.model import MessageClass
from ...inputs.records import InputError, Notice, Record, Unreadable
from .catalog import Catalog, SourceMapping
from .columnar import convert_columns
from .columns import ConceptColumn, NDArray
from .sources import Batch, instances_to_columns

INFO = "dronecan.uavcan.equipment.power.BatteryInfo"
AUX = "dronecan.ardupilot.equipment.power.BatteryInfoAux"
CBAT = "dronecan.cuav.equipment.power.CBAT"
MESSAGES = ((INFO, AUX), (CBAT,))  # each read with its companions
# UDRAL's battery service (read where --cyphal-subject names its subjects: Cyphal/CAN frames carry no type)
UDRAL = (
    "cyphal.reg.udral.physics.electricity.SourceTs_0_1",
    "cyphal.reg.udral.service.battery.Status_0_2",
    "cyphal.reg.udral.service.battery.Parameters_0_3",
)
ModelOf = Callable[[Catalog, str], MessageClass]


# said where a capture read as DroneCAN gave no battery record but had start frames as Cyphal/CAN sends them
CYPHAL_LIKE = (
    "no battery records; its start frames are Cyphal/CAN's (toggle bit set): give --cyphal-subject ID=TYPE for the "
    "subjects its UDRAL batteries publish (energy_source, status, parameters)"
)
STREAM_ABOVE = 8 << 20  # bytes: a larger capture is read twice, its batteries handed out in chunks (flat memory)
CHUNK = 1 << 16  # records per batch of a capture read twice


def can_batches(
    path: Path, name: str, catalog: Catalog, model_of: ModelOf, subjects: Sequence[str] = ()
) -> Iterator[Batch]:
    """Every battery node's batches of a capture; raises InputError if the capture is unreadable. A capture of up
    to :data:`STREAM_ABOVE` bytes is read once, each node's message one batch; a larger one twice -- first to
    learn which battery ids the nodes use (the numbering needs them all), then handing out each node's records
    every :data:`CHUNK` -- so memory stays flat whatever its length. Both give the same records. ``subjects``: the
    ``--cyphal-subject`` pairs; given, UDRAL's SourceTs records (with their node's Status and Parameters) too."""
    try:
        streamed = path.stat().st_size > STREAM_ABOVE
    except OSError:
        streamed = False  # the reader says why it cannot read it
    notes: list[str] = []
    if not streamed:
        out = list(_walk(path, name, catalog, model_of, notes, None, subjects))
        if not out and CYPHAL_LIKE in notes:
            raise InputError(name, 0, CYPHAL_LIKE)
        shared = _shared_ids(_battery_ids(out))
        yield from _finished(out, shared, _told(notes, shared), capture_start(path, name) if out else None)
        return
    ids: dict[int, set[int]] = {}
    for batch in _walk(path, name, catalog, model_of, [], CHUNK, subjects):
        for node, found in _battery_ids([batch]).items():
            ids.setdefault(node, set()).update(found)
    shared = _shared_ids(ids)
    start = capture_start(path, name)
    previous: Batch | None = None
    for batch in _walk(path, name, catalog, model_of, notes, CHUNK, subjects):
        if previous is not None:
            yield from _finished([previous], shared, [], start)
        previous = batch
    if previous is not None:  # the notes (damage counts) are known once the capture is read: on its last batch
        yield from _finished([previous], shared, _told(notes, shared), start)
    elif CYPHAL_LIKE in notes:
        raise InputError(name, 0, CYPHAL_LIKE)


def _told(notes: list[str], shared: str | None) -> list[str]:
    return notes + ([shared] if shared else [])


def _walk(
    path: Path,
    name: str,
    catalog: Catalog,
    model_of: ModelOf,
    notes: list[str],
    chunk: int | None,
    subjects: Sequence[str],
) -> Iterator[Batch]:
    """Each node's records of each message as batches: at most ``chunk`` records each (None: one per node)."""
    # the damage is counted once: by the pass that reads the bus as it is (both protocols where subjects are given)
    counted = UDRAL[0] if subjects else INFO
    for qualified in (*MESSAGES, UDRAL) if subjects else MESSAGES:
        models = [model_of(catalog, q) for q in qualified]
        by_node: dict[int, list[Record]] = {}
        damaged: list[str] = []
        for item in capture_side(path, name, models, subjects):
            if isinstance(item, Record):
                node = int(cast(int, (item.location or {}).get("node", 0)))
                records = by_node.setdefault(node, [])
                records.append(item)
                if chunk is not None and len(records) == chunk:
                    yield _batch(catalog, qualified, node, records)
                    by_node[node] = []
            elif isinstance(item, Unreadable):
                damaged.append(item.message)
            elif isinstance(item, Notice):
                if item.kind == "empty" and item.severity == "error":
                    raise InputError(name, 0, item.message)
                if item.kind == "transport" and item.severity == "error" and qualified[0] == counted:
                    damaged.append(item.message)
                if (item.data or {}).get("code") == "can-cyphal-like" and CYPHAL_LIKE not in notes:
                    notes.append(CYPHAL_LIKE)
        if damaged:
            notes.append(f"{len(damaged)} damaged or undecodable transfers skipped (first: {damaged[0]})")
        for node, records in sorted(by_node.items()):
            if records:
                yield _batch(catalog, qualified, node, records)


def _finished(batches: list[Batch], shared: str | None, notes: list[str], start: float | None) -> list[Batch]:
    """Batches numbered (``shared``: the note saying the nodes share an id, so they are numbered by node), timed
    (``start``: the capture's absolute first stamp, if it has one), the first of them given ``notes``."""
    for b in batches:
        if shared is not None:
            assert b.concepts is not None
            b.concepts["battery_index"].set(np.asarray(b.instance, np.int64))
        if start is not None:  # absolute stamps: the time of day of each record
            origin = round(start * 1e6)
            b.utc_offset_us = origin
            b.time_us = np.round(b.t * 1e6).astype(np.int64) + origin
    if batches:
        batches[0].notes.extend(notes)
    return batches


def _batch(catalog: Catalog, qualified: Sequence[str], node: int, records: list[Record]) -> Batch:
    n = len(records)
    main = qualified[0]
    instances = [r.instance for r in records]
    columns = instances_to_columns(catalog.schema.message(main), instances, catalog.schema, catalog.source(main).fields)
    t = np.array([float(cast(float, (r.location or {}).get("t", np.nan))) for r in records])
    batch = Batch(main, n, columns, t, np.full(n, node))
    concepts = convert_columns(catalog, catalog.source(main), columns, n)
    for position, companion in enumerate(qualified[1:]):
        rows = np.array([r.companions[position] is not None for r in records], bool)
        if not rows.any():
            continue
        seen = [m for m in (r.companions[position] for r in records) if m is not None]
        mapping = catalog.companions[companion]
        aux_columns = instances_to_columns(mapping.message, seen, catalog.schema, mapping.fields)
        aux = convert_columns(catalog, mapping, aux_columns, len(seen))
        for concept, column in aux.items():
            _fill(concepts[concept], column, rows)
    together = catalog.joint.get(main)
    if together is not None:
        _joint(catalog, together, qualified, records, concepts)
    batch.concepts = concepts
    return batch


def _joint(
    catalog: Catalog,
    mapping: SourceMapping,
    qualified: Sequence[str],
    records: list[Record],
    concepts: dict[str, ConceptColumn],
) -> None:
    """The rules reading several companions together (UDRAL's SoC from Status and Parameters), on the records
    beside which the node had sent each of them; like a companion's, they fill only what is still unknown."""
    read = {s.message for rule in mapping.rules for s in rule.sources}
    positions = [i for i, q in enumerate(qualified[1:]) if q in read]
    rows = np.array([all(r.companions[i] is not None for i in positions) for r in records], bool)
    if not rows.any():
        return
    columns: dict[str, NDArray] = {}
    for i in positions:
        message = catalog.schema.message(qualified[1 + i])
        paths = {s.field for rule in mapping.rules for s in rule.sources if s.message == message.qualified_name}
        seen = [r.companions[i] for r, ok in zip(records, rows, strict=True) if ok]
        found = instances_to_columns(message, seen, catalog.schema, paths)
        columns.update((k, v) for k, v in found.items() if k.partition("#")[0] in paths)
    for concept, column in convert_columns(catalog, mapping, columns, int(rows.sum())).items():
        _fill(concepts[concept], column, rows)


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


def _battery_ids(batches: list[Batch]) -> dict[int, set[int]]:
    """The battery ids each node's records give."""
    ids: dict[int, set[int]] = {}
    for b in batches:
        assert b.concepts is not None
        index = b.concepts["battery_index"]
        ids.setdefault(int(b.instance[0]), set()).update(int(v) for v in index.values[index.valid])
    return ids


def _shared_ids(ids: dict[int, set[int]]) -> str | None:
    """battery_id is the battery, unless two nodes share one: then every battery is numbered by its node id, and
    this says so (None where no id is shared)."""
    owners: dict[int, set[int]] = {}
    for node, found in ids.items():
        for battery in found:
            owners.setdefault(battery, set()).add(node)
    shared = sorted(b for b, nodes in owners.items() if len(nodes) > 1)
    if not shared:
        return None
    return f"nodes {', '.join(map(str, sorted(ids)))} share battery_id {shared[0]}: batteries numbered by node id"
