"""Devicetree instances: read .dts/.dtsi source and .dtb blobs into DtNodes, and map nodes onto
the generated devicetree models.

    nodes = read_dts(Path("board.dts"))            # or read_dtb(Path("board.dtb"))
    for node in find_compatible(nodes, "simple-battery"):
        battery = SimpleBattery.from_dict(node_to_model_dict(node, message))

Source input must be preprocessed already when it uses #include / #define (dtc's own /include/
is read here); errors name the file and line and say what was expected.
"""

from __future__ import annotations

from .dtb import Blob
from .mapping import (
    GENERIC_PROPERTIES,
    by_phandle,
    field_for,
    find_compatible,
    is_generic,
    monitored_batteries,
    node_to_model_dict,
    nodes_for_message,
)
from .model import DevicetreeError, DtNode, DtPart, DtValue
from .reading import read_dtb, read_dtb_blob, read_dts, read_nodes

__all__ = [
    "GENERIC_PROPERTIES",
    "Blob",
    "DevicetreeError",
    "DtNode",
    "DtPart",
    "DtValue",
    "by_phandle",
    "field_for",
    "find_compatible",
    "is_generic",
    "monitored_batteries",
    "node_to_model_dict",
    "nodes_for_message",
    "read_dtb",
    "read_dtb_blob",
    "read_dts",
    "read_nodes",
]
