"""Reading devicetree files into DtNodes: .dts/.dtsi source and .dtb blobs."""

from __future__ import annotations

from pathlib import Path

from ...text.files import display_path, read_whole
from .dtb import Blob, parse_dtb
from .model import DevicetreeError, DtNode
from .parse import Parser
from .tree import finish


def read_dts(path: Path, *, root: Path | None = None) -> list[DtNode]:
    """Every node of a .dts (or a self-contained .dtsi), root first, in document order."""
    display = display_path(path, root)
    parser = Parser(path, display, root)
    tree = parser.parse(require_header=path.suffix != ".dtsi")
    return finish(tree)


def read_dtb_blob(path: Path, *, root: Path | None = None) -> Blob:
    display = display_path(path, root)
    return parse_dtb(read_whole(path, display, DevicetreeError, "a devicetree blob"), display)


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
