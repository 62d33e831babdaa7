"""Reading Cyphal DSDL through pydsdl: which folders are root namespaces, the limits applied first,
and pydsdl's errors turned into ``file:line: ...`` ones.

A *root* is a folder holding root namespace folders (``root/uavcan/``, ``root/reg/``), as a checkout of
the public regulated data types is. Each root namespace is read with the others as pydsdl's lookup
directories, so a vendor namespace may use the regulated types beside it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TypeVar

import pydsdl

from ...errors import ErrorCollector, SchemaError
from ...text.files import display_path
from ...text.limits import read_schema_text

_T = TypeVar("_T")
SUFFIX = ".dsdl"
_SEARCH_LIMIT = 20_000  # directory entries looked at below one root (never a whole disk)


def _dsdl_files(folder: Path) -> Iterator[Path]:
    for seen, path in enumerate(sorted(folder.rglob("*" + SUFFIX))):
        if seen >= _SEARCH_LIMIT:
            raise SchemaError(folder.as_posix(), 0, f"expected at most {_SEARCH_LIMIT} DSDL files below a root")
        if path.is_file():
            yield path


def has_definitions(folder: Path) -> bool:
    """Some ``*.dsdl`` file lies below ``folder`` (a bounded walk)."""
    for seen, path in enumerate(folder.rglob("*")):
        if seen >= _SEARCH_LIMIT:
            return False
        if path.suffix == SUFFIX and path.is_file():
            return True
    return False


def root_namespaces(root: Path) -> list[Path]:
    """The root namespace folders of ``root``: its sub-folders holding definitions."""
    if not root.is_dir():
        raise SchemaError(root.as_posix(), 0, "expected a folder holding Cyphal root namespaces (uavcan/, reg/, ...)")
    found = [sub for sub in sorted(root.iterdir()) if sub.is_dir() and has_definitions(sub)]
    if not found:
        raise SchemaError(root.as_posix(), 0, "expected root namespace folders holding *.dsdl definitions")
    return found


def check_limits(files: Sequence[Path], root: Path) -> None:
    """Every file within the schema limits (size, number length) before pydsdl sees it."""
    found = ErrorCollector()
    for path in files:
        with found.step():
            read_schema_text(path, display_path(path, root))
    found.raise_if_any()


def read_root(root: Path) -> list[pydsdl.CompositeType]:
    """Every type below ``root``, each root namespace read once (pydsdl checks port id clashes in it)."""
    spaces = root_namespaces(root)
    check_limits([p for space in spaces for p in _dsdl_files(space)], root)
    types: list[pydsdl.CompositeType] = []
    found = ErrorCollector()
    for space in spaces:
        lookups = [other for other in spaces if other != space]
        with found.step():
            types += _pydsdl(root, lambda: pydsdl.read_namespace(space, lookups))  # noqa: B023 (called at once)
    found.raise_if_any()
    return types


def read_file(path: Path, root: Path) -> list[pydsdl.CompositeType]:
    """One definition and every type it uses (looked up in the root namespaces of ``root``)."""
    spaces = root_namespaces(root)
    own = next((s for s in spaces if s.resolve() in path.resolve().parents), None)
    if own is None:
        raise SchemaError(display_path(path, root), 0, f"expected the file below a root namespace of {root}")
    check_limits([path], root)
    lookups = [s for s in spaces if s != own]
    direct, used = _pydsdl(root, lambda: pydsdl.read_files([path], [own], lookups))
    return [*direct, *used]


def find_root(path: Path) -> Path:
    """The root of a definition given alone: the parent of the top-most ancestor whose folders up to the
    file are all namespace components (identifiers), as pydsdl names namespaces after folders."""
    parents = list(path.resolve().parents)
    top = 0
    while top + 1 < len(parents) and parents[top].name.isidentifier():
        top += 1
    return parents[top]


def _pydsdl(root: Path, read: Callable[[], _T]) -> _T:
    try:
        return read()
    except pydsdl.FrontendError as error:
        where = display_path(Path(error.path), root) if error.path else root.as_posix()
        raise SchemaError(where, error.line or 0, f"expected valid Cyphal DSDL (pydsdl: {error.text})") from None
