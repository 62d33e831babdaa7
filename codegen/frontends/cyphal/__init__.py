"""Cyphal (UAVCAN v1) DSDL frontend: ``*.dsdl`` definitions -> IR, read by pydsdl, the reference parser.

Layout: a *root* folder holds root namespace folders, as a copy of the public regulated data types does
(``root/reg/udral/service/battery/Status.0.2.dsdl`` is ``reg.udral.service.battery.Status`` version 0.2).
``parse_dir(root)`` reads every definition below it; ``parse_file(path, root=...)`` one definition and the
types it uses. Without ``root`` the root is the parent of the top-most ancestor folder whose name, like
every folder between it and the file, is a namespace component.

pydsdl decides everything it knows (bit lengths, alignment, ``@sealed`` / ``@extent``, unions, port ids,
the checks of the specification); :mod:`.build` turns its types into IR and :mod:`.semantics` adds what
the regulated types say in names and docs (units, UDRAL's NaN sentinels, enums). ``reg.drone`` (UDRAL's
former name) is read as ``reg.udral``. pydsdl's errors become ``file:line: expected ...`` errors.
"""

from __future__ import annotations

from pathlib import Path

from ...ir import Schema
from .build import build
from .reading import find_root, has_definitions, read_file, read_root

__all__ = ["find_root", "has_definitions", "parse_dir", "parse_file"]


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One definition and every type it uses (found in the root namespaces of ``root``)."""
    base = find_root(path) if root is None else root
    return build(read_file(path, base), base)


def parse_dir(root: Path) -> Schema:
    """Every ``*.dsdl`` below the root folder ``root``."""
    return build(read_root(root), root)
