"""DSDL v0 names: definition file names, namespace components, full type names."""

from __future__ import annotations

import re

from ...errors import SchemaError

MAX_FULL_NAME_LEN = 80

_NAMESPACE_RE = re.compile(r"[a-z][a-z0-9_]*\Z")
_TYPE_NAME_RE = re.compile(r"[A-Z][A-Za-z0-9_]*\Z")


def valid_namespace_component(name: str) -> bool:
    return bool(_NAMESPACE_RE.match(name))


def valid_type_name(name: str) -> bool:
    """A short type name: CamelCase, starting with a capital letter."""
    return bool(_TYPE_NAME_RE.match(name))


def split_file_name(basename: str) -> tuple[int | None, str, tuple[int, int] | None] | None:
    """``[<id>.]<Name>[.<major>.<minor>].uavcan`` -> (id, name, version); None if not that shape."""
    items = basename.split(".")
    if len(items) not in (2, 3, 4, 5) or items[-1] != "uavcan":
        return None
    has_id = len(items) in (3, 5)
    dtid_text, name = (items[0], items[1]) if has_id else (None, items[0])
    version_items = items[-3:-1] if len(items) >= 4 else None
    if dtid_text is not None and not dtid_text.isdigit():
        return None
    if version_items is not None and not all(v.isdigit() for v in version_items):
        return None
    version = (int(version_items[0]), int(version_items[1])) if version_items else None
    return (int(dtid_text) if dtid_text is not None else None), name, version


def check_full_name(full_name: str, file: str, line: int) -> None:
    namespace, _, short = full_name.rpartition(".")
    if not namespace:
        raise SchemaError(file, line, f"expected a type inside a namespace, got {full_name!r}")
    for component in namespace.split("."):
        if not valid_namespace_component(component):
            raise SchemaError(
                file, line, f"expected namespace components of lowercase letters, digits and '_', got {component!r}"
            )
    if not valid_type_name(short):
        raise SchemaError(file, line, f"expected a CamelCase type name, got {short!r}")
    if len(full_name) > MAX_FULL_NAME_LEN:
        raise SchemaError(file, line, f"expected a full type name of at most {MAX_FULL_NAME_LEN} characters")
