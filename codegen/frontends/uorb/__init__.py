"""PX4 uORB ``.msg`` frontend.

A message is named by its file (``BatteryStatus.msg`` -> ``uorb.BatteryStatus``); a field type
that is not builtin names another ``.msg`` in the same directory. Each message carries its PX4
C-struct layout (:mod:`.layout`), which needs the sizes of nested messages, so parsing a file also
parses the files it nests; the returned Schema includes them.

The work is done in: :mod:`.syntax` (the lines of a file), :mod:`.values` (literals),
:mod:`.annotations` (field comment metadata), :mod:`.enums` (constants grouped into enums),
:mod:`.layout` (struct layout) and :mod:`.build` (files -> IR messages).
"""

from __future__ import annotations

from pathlib import Path

from ...errors import SchemaError
from ...ir import Schema
from ...text.files import display_path
from .build import Loader, NestedFailure

__all__ = ["parse_dir", "parse_file"]


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One .msg file, plus the messages it nests (their sizes shape its layout)."""
    loader = Loader(root)
    try:
        loader.load(path)
    except NestedFailure:
        pass  # its errors are in loader.errors
    loader.raise_errors()
    return loader.schema()


def parse_dir(root: Path) -> Schema:
    """Every .msg file below ``root``, in sorted path order; errors of all files in one ErrorList."""
    if not root.is_dir():
        raise SchemaError(display_path(root, None), 0, "expected a directory of .msg files")
    loader = Loader(root)
    for path in sorted(root.rglob("*.msg")):
        if path.is_file():
            try:
                loader.load(path)
            except NestedFailure:
                continue  # reported in loader.errors (or, for a file nesting it, there already)
    loader.raise_errors()
    return loader.schema()
