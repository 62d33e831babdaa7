"""Devicetree nodes as records: the nodes compatible with a binding, as the model's plain data.

A node's record is located at the node's line (in the file that defined it, which may be an
included one) and names its path; a property's violation points at the property's line.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ...errors import BattgenError
from ...ir import Message
from ..records import Item, Record, Unreadable, first_field_locator
from .mapping import node_to_model_dict, nodes_for_message
from .model import DtNode
from .reading import read_dtb, read_dts


def read_devicetree(path: Path, name: str, message: Message, *, binary: bool) -> Iterator[Item]:
    """The records of a .dts/.dtsi (or, ``binary``, a .dtb) for a devicetree message; the file is
    read before the first record (DevicetreeError names file and line)."""
    nodes = read_dtb(path) if binary else read_dts(path)
    return _items(name, message, nodes_for_message(nodes, message))


def _items(name: str, message: Message, nodes: list[DtNode]) -> Iterator[Item]:
    for index, node in enumerate(nodes):
        file = node.file or name
        try:
            data = node_to_model_dict(node, message)
        except BattgenError as exc:
            yield Unreadable(file, node.line, f"{node.path}: {exc}")
            continue
        lines = {prop: value.line for prop, value in node.properties.items() if value.line > 0}
        yield Record(index, node.line, data, file, where=node.path, locate=first_field_locator(lines))
