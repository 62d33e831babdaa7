"""DroneCAN (UAVCAN v0) DSDL frontend: ``*.uavcan`` definitions -> IR.

Layout: a DSDL *root* directory holds root namespaces (``root/uavcan/equipment/power/
1092.BatteryInfo.uavcan`` is ``uavcan.equipment.power.BatteryInfo`` with default data type id
1092). ``parse_dir(root)`` parses every ``*.uavcan`` below root; ``parse_file(path, root=...)``
parses one definition plus every type it references (looked up below the same root), so each
:class:`~codegen.ir.CompositeType` resolves inside the returned Schema.

Without ``root``, ``parse_file`` walks up from the file: the root is the top-most ancestor named
``dsdl_specs`` or ``dsdl``; failing that, the top-most ancestor named ``dronecan``; in both cases
only if every directory between it and the file is a valid namespace component. Failing both,
the file's grandparent is the root, i.e. its directory is a one-component namespace. Pass
``root`` explicitly whenever the tree does not follow one of these conventions.

A service becomes two messages, ``dronecan.<full name>.Request`` and ``.Response`` (named
``<Short>Request`` / ``<Short>Response``), sharing the service's id and signature.

The work is done in: :mod:`.namespaces` (root, files, references), :mod:`.names` (file and type
names), :mod:`.syntax` (one file's text -> :mod:`.definitions`, constant initialisers by :mod:`.expr`),
:mod:`.signature` (signatures, bit lengths), :mod:`.semantics` (docs, units, enums, sentinels) and
:mod:`.build` (IR messages).
"""

from __future__ import annotations

from pathlib import Path

from ...errors import ErrorCollector, SchemaError
from ...ir import Schema
from .build import build
from .namespaces import Namespaces, find_root

__all__ = ["find_root", "parse_dir", "parse_file"]


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One definition and every type it references (found below ``root``, or the root found from the path)."""
    namespaces = Namespaces(find_root(path) if root is None else root)
    namespaces.load_path(path)
    return build(namespaces.defs)


def parse_dir(root: Path) -> Schema:
    """Every ``*.uavcan`` below the DSDL root ``root``, in sorted path order; default ids must be unique."""
    if not root.is_dir():
        raise SchemaError(root.as_posix(), 0, "expected a DSDL root directory")
    namespaces = Namespaces(root)
    found = ErrorCollector()  # every file's errors in one report
    for path in sorted(root.rglob("*.uavcan")):
        if path.is_file():
            with found.step():
                namespaces.load_path(path)
    found.raise_if_any()
    namespaces.check_unique_ids()
    return build(namespaces.defs)
