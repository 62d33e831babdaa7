"""Devicetree instances: read .dts/.dtsi source and .dtb blobs into DtNodes, and map nodes onto
the generated devicetree models.

    nodes = read_dts(Path("board.dts"))            # or read_dtb(Path("board.dtb"))
    for node in find_compatible(nodes, "simple-battery"):
        battery = SimpleBattery.from_dict(node_to_model_dict(node, message))

Source input must be preprocessed already when it uses #include / #define (dtc's own /include/
is read here); errors name the file and line and say what was expected.
"""

from __future__ import annotations

from pathlib import Path

from ...text.files import display_path
from .dtb import Blob, parse_dtb
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
from .parse import Parser
from .tree import finish

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


def read_dts(path: Path, *, root: Path | None = None) -> list[DtNode]:
    """Every node of a .dts (or a self-contained .dtsi), root first, in document order."""
    display = display_path(path, root)
    parser = Parser(path, display, root)
    tree = parser.parse(require_header=path.suffix != ".dtsi")
    return finish(tree)


def read_dtb_blob(path: Path, *, root: Path | None = None) -> Blob:
    display = display_path(path, root)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise DevicetreeError(display, 0, f"cannot read file: {exc.strerror or exc}") from None
    return parse_dtb(data, display)


def read_dtb(path: Path, *, root: Path | None = None) -> list[DtNode]:
    """Every node of a flattened devicetree blob, root first, in blob order."""
    return read_dtb_blob(path, root=root).nodes


def read_nodes(path: Path, *, root: Path | None = None) -> list[DtNode]:
    """read_dtb for .dtb/.dtbo files and blobs with the FDT magic, read_dts otherwise."""
    if path.suffix in (".dtb", ".dtbo"):
        return read_dtb(path, root=root)
    try:
        with path.open("rb") as fh:
            head = fh.read(4)
    except OSError:
        head = b""
    if head == b"\xd0\x0d\xfe\xed":
        return read_dtb(path, root=root)
    return read_dts(path, root=root)
