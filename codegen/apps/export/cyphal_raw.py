"""``--raw`` for Cyphal/CAN captures: every type ``--cyphal-subject`` names, each as its own table.

The battery view reads UDRAL's SourceTs as records and its node's Status and Parameters only as companions (the
latest of each beside every SourceTs), so their own transfers never reach a raw table through it. Here each subject's
type is read on its own through the capture reader (:func:`codegen.inputs.can.records.capture_items`: the same
reassembly, CRC checks and generated decoders as the view), a table per type: every transfer one row, with its node
as the instance and the capture's clock as ``t``. A composite field (Cyphal's ``uavcan.si`` Scalars, a fixed array
of them, a nested Power or Source) is its numbers by their dotted paths (``value.power.voltage.volt``,
``temperature_min_max.1.kelvin``), each with its unit, as the view's raw tables name them; a variable-length array
of composites has no fixed columns and is left out.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, cast

import numpy as np

from ...inputs.can.cyphal_ports import cyphal_classes, subject_table
from ...inputs.can.records import capture_items
from ...inputs.model import CyphalClass
from ...inputs.records import Record
from ...ir import ArrayType, CompositeType, Message, Schema
from ..battery.sources import Batch, instances_to_columns
from .dataset import raw_table

CYPHAL_PREFIX = "cyphal."  # the qualified names of Cyphal types (the view's own batches of them are not raw-written)
CHUNK = 1 << 16  # rows of one node's table written at a time: a long capture in flat memory


def number_paths(message: Message, schema: Schema, prefix: str = "") -> Iterator[str]:
    """The dotted paths of the numbers and arrays inside ``message``'s composite fields (a fixed array of
    composites element by element); the message's own plain fields are not paths (the table has them by name)."""
    for f in message.fields:
        if f.is_padding:
            continue
        here = f"{prefix}{f.name}"
        t = f.type
        if isinstance(t, CompositeType):
            yield from _inside(schema.message(t.name), schema, here)
        elif isinstance(t, ArrayType) and isinstance(t.element, CompositeType):
            if not t.dynamic and t.capacity is not None:
                for i in range(t.capacity):
                    yield from _inside(schema.message(t.element.name), schema, f"{here}.{i}")
        elif prefix:
            yield here


def _inside(message: Message, schema: Schema, here: str) -> Iterator[str]:
    yield from number_paths(message, schema, here + ".")


def cyphal_raw_tables(
    path: Path, name: str, log: str, subjects: Sequence[str], schema: Schema, package: str
) -> Iterator[tuple[str, Any]]:
    """``(message, table)`` for each subject type's transfers of each node, at most :data:`CHUNK` rows a table;
    ``schema``: the one the types are in, ``package``: the generated package decoding them."""
    classes = subject_table(subjects, cyphal_classes(package))
    given = {int(p.partition("=")[0]) for p in subjects}  # the pairs' types, not every fixed port id's
    seen: list[CyphalClass] = []
    for port, cls in sorted(classes.items()):
        if port in given and cls not in seen:
            seen.append(cls)
    for cls in seen:
        message = schema.message(cls.QUALIFIED_NAME)
        paths = list(number_paths(message, schema))
        by_node: dict[int, list[Record]] = {}
        for item in capture_items(path, name, cls, subjects):
            if not isinstance(item, Record):
                continue  # damage is the view's to count (its notes); here only what decodes
            node = int(cast(int, (item.location or {}).get("node", 0)))
            records = by_node.setdefault(node, [])
            records.append(item)
            if len(records) == CHUNK:
                yield message.qualified_name, _table(message, schema, paths, node, records, log)
                by_node[node] = []
        for node, records in sorted(by_node.items()):
            if records:
                yield message.qualified_name, _table(message, schema, paths, node, records, log)


def _table(message: Message, schema: Schema, paths: list[str], node: int, records: list[Record], log: str) -> Any:
    columns = instances_to_columns(message, [r.instance for r in records], schema, paths)
    t = np.array([float(cast(float, (r.location or {}).get("t", np.nan))) for r in records])
    batch = Batch(message.qualified_name, len(records), columns, t, np.full(len(records), node))
    return raw_table(message, batch, log, schema)
