"""MAVLink XML frontend: dialect files (with their <include>s) -> IR.

The modules, in the order a dialect passes through them: :mod:`.includes` reads each file and
what it includes, :mod:`.scan` pre-checks it for safety (before pymavlink's parser runs on it),
:mod:`.build` turns pymavlink's results into IR, using :mod:`.values` for attribute literals and
:mod:`.layout` for the wire layout (field order, lengths, CRC_EXTRA).

Bad files do not stop the others: the files that read are built, and every error of the run (files
that do not read, messages that do not build) comes in one ErrorList.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ...errors import ErrorCollector
from ...ir import Schema
from .build import build
from .includes import read_dialects

__all__ = ["parse_dir", "parse_file"]


def parse_file(path: Path, *, root: Path | None = None, include_paths: Sequence[Path] = ()) -> Schema:
    """One dialect file and everything it includes (from its folder, or root, and include_paths)."""
    return _parse([path], root, include_paths)


def parse_dir(root: Path, *, include_paths: Sequence[Path] = ()) -> Schema:
    """Every *.xml below root (sorted); shared includes are read once (from root and include_paths)."""
    return _parse(sorted(p for p in root.rglob("*.xml") if p.is_file()), root, include_paths)


def _parse(paths: list[Path], root: Path | None, include_paths: Sequence[Path]) -> Schema:
    found = ErrorCollector()
    files = read_dialects(paths, root, include_paths, found)
    schema = Schema()
    with found.step():
        schema = build(files)
    found.raise_if_any()
    return schema
