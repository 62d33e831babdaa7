"""Pick the frontend for each input and merge what they produce into one Schema.

Like a compiler, a load reports every error in one run: each format folder and each path given is
parsed even when an earlier one failed, and the errors of all of them are raised together as one
:class:`~codegen.errors.ErrorList` (the frontends collect theirs per file and line the same way).
Mappings and rules are checked only when the formats they refer to parsed cleanly, since a
message missing because its file is broken would otherwise be reported again from every mapping.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence
from pathlib import Path
from typing import Protocol

from ..errors import BattgenError, ErrorList, SchemaError
from ..ir import EnumDef, Schema
from . import cyphal, devicetree, dsdl, mavlink, pdef, rules, uorb


class Frontend(Protocol):
    """What a format's frontend package offers: a folder of its files, or one file, parsed into IR."""

    def parse_dir(self, root: Path, /) -> Schema: ...

    def parse_file(self, path: Path, /, *, root: Path | None = None) -> Schema: ...


# schema folder layout: one sub-folder per format, each handled by one frontend package
FORMAT_FRONTENDS: dict[str, Frontend] = {
    "uorb": uorb,
    "dronecan": dsdl,
    "devicetree": devicetree,
    "mavlink": mavlink,
    "params": pdef,  # ArduPilot parameter metadata (apm.pdef.xml)
    "cyphal": cyphal,  # Cyphal v1 DSDL root namespaces (uavcan/, reg/), read by pydsdl
}

# converter mappings between the formats (schemas/mappings/*.yaml), parsed after the formats
MAPPINGS_DIR = "mappings"
# cross-field rules the validators compile (schemas/rules/*.yaml), also read after the formats
RULES_DIR = "rules"

EXTENSION_FORMATS: dict[str, str] = {
    ".msg": "uorb",
    ".uavcan": "dronecan",
    ".dsdl": "cyphal",
    ".yaml": "devicetree",
    ".yml": "devicetree",
    ".xml": "mavlink",
    ".pdef.xml": "params",  # ArduPilot parameter metadata; checked before the plain suffix
}


def frontend(fmt: str) -> Frontend:
    return FORMAT_FRONTENDS[fmt]


def format_of_file(path: Path) -> str:
    name = path.name.lower()
    fmt = EXTENSION_FORMATS.get(".pdef.xml") if name.endswith(".pdef.xml") else None
    fmt = fmt or EXTENSION_FORMATS.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted(EXTENSION_FORMATS))
        raise BattgenError(f"{path}: cannot tell the schema format from the extension (expected one of {known})")
    return fmt


def is_schema_dir(path: Path) -> bool:
    return any((path / fmt).is_dir() for fmt in FORMAT_FRONTENDS)


def load_schema_dir(root: Path, *, include_paths: Sequence[Path] = (), only: Collection[str] | None = None) -> Schema:
    """A folder laid out as uorb/, dronecan/, devicetree/, mavlink/ (any subset); MAVLink includes
    may also come from ``include_paths`` (docs/limits.md). ``only``: the sub-folders to read (format
    folders, ``mappings``, ``rules``), for a caller that needs just those; every one when None."""
    schema = Schema()
    errors: list[BattgenError] = []
    for fmt in FORMAT_FRONTENDS:
        sub = root / fmt
        if sub.is_dir() and (only is None or fmt in only):
            try:
                part: Schema = (
                    mavlink.parse_dir(sub, include_paths=include_paths)
                    if fmt == "mavlink"
                    else frontend(fmt).parse_dir(sub)
                )
            except BattgenError as error:
                errors.append(error)
                continue
            schema = schema.merged(part)
    ErrorList.raise_if_any(errors)
    if (root / MAPPINGS_DIR).is_dir() and (only is None or MAPPINGS_DIR in only):
        # after the formats, so every reference to a message or field can be checked
        from . import mappings

        schema = schema.merged(mappings.parse_dir(root / MAPPINGS_DIR, schema=schema))
    if (root / RULES_DIR).is_dir() and (only is None or RULES_DIR in only):
        schema = schema.merged(Schema(rules=rules.load_rules_dir(root / RULES_DIR)))
        rules.check_rules(schema)  # after the formats: every rule must bind to the messages it names
    return schema


_OWN_FOLDERS = frozenset(FORMAT_FRONTENDS) | {MAPPINGS_DIR, RULES_DIR}
_SEARCH_LIMIT = 10_000  # directory entries looked at while telling a DSDL tree from a schema folder


def _first_dsdl(folder: Path) -> Path | None:
    """Some ``*.uavcan`` file below ``folder`` (a bounded walk: never a whole disk)."""
    for seen, path in enumerate(folder.rglob("*")):
        if seen >= _SEARCH_LIMIT:
            return None
        if path.suffix == ".uavcan" and path.is_file():
            return path
    return None


def dsdl_definition(path: Path) -> Path | None:
    """A definition that makes ``path`` a DSDL tree rather than a schema folder, if it is one: a
    ``*.uavcan`` file in it or below a namespace folder (``uavcan/``, ``ardupilot/``, ...), with none
    of a schema folder's other format folders. A ``dronecan/`` folder alone keeps its schema-folder meaning."""
    if any((path / name).is_dir() for name in _OWN_FOLDERS - {"dronecan"}):
        return None
    direct = next((p for p in sorted(path.glob("*.uavcan")) if p.is_file()), None)
    if direct is not None:
        return direct
    for sub in sorted(path.iterdir()):
        if sub.is_dir() and sub.name != "dronecan":
            found = _first_dsdl(sub)
            if found is not None:
                return found
    return None


def is_cyphal_root(path: Path) -> bool:
    """A folder of Cyphal root namespaces (a copy of the public regulated data types, say): a sub-folder
    holding ``*.dsdl`` definitions, and none of a schema folder's format folders."""
    if any((path / name).is_dir() for name in _OWN_FOLDERS):
        return False
    return any(sub.is_dir() and cyphal.has_definitions(sub) for sub in sorted(path.iterdir()))


def _load_dsdl_tree(path: Path, definition: Path) -> Schema:
    """A DSDL root; a folder inside one (a namespace) is refused with the root to pass instead."""
    root = dsdl.find_root(definition)
    if definition.parent.resolve() == path.resolve() or root.resolve() in path.resolve().parents:
        raise BattgenError(
            f"{path}: a DSDL namespace folder, not a DSDL root: pass the folder holding its top namespace, {root}"
        )
    return dsdl.parse_dir(path)


def load(paths: Iterable[Path], *, include_paths: Sequence[Path] = (), only: Collection[str] | None = None) -> Schema:
    """Parse schema folders, DSDL roots, folders of .msg files and single files (format from the
    extension) into one Schema; the errors of every path are raised together. ``include_paths``:
    folders MAVLink <include>s may read besides the schema folder; ``only``: the sub-folders of a
    schema folder to read (:func:`load_schema_dir`)."""
    schema = Schema()
    errors: list[BattgenError] = []
    for path in paths:
        try:
            part = _load_path(path, include_paths, only)
        except BattgenError as error:
            errors.append(error)
            continue
        schema = schema.merged(part)
    ErrorList.raise_if_any(errors)
    return _deduplicated(schema)


def _load_path(path: Path, include_paths: Sequence[Path], only: Collection[str] | None = None) -> Schema:
    if path.is_dir():
        definition = dsdl_definition(path)
        if definition is not None:
            return _load_dsdl_tree(path, definition)
        if is_schema_dir(path):
            return load_schema_dir(path, include_paths=include_paths, only=only)
        if is_cyphal_root(path):
            return cyphal.parse_dir(path)
        if any(p.is_file() for p in path.glob("*.msg")):
            return frontend("uorb").parse_dir(path)  # a folder of .msg files, as PX4's own msg/
        expected = ", ".join(f"{f}/" for f in FORMAT_FRONTENDS)
        raise BattgenError(
            f"{path}: not a schema folder (expected sub-folders {expected}) nor a DSDL root "
            "(namespace folders such as uavcan/ holding .uavcan or Cyphal .dsdl files) nor a folder of .msg files"
        )
    if path.is_file():
        fmt = format_of_file(path)
        if fmt == "mavlink":
            return mavlink.parse_file(path, include_paths=include_paths)
        return frontend(fmt).parse_file(path)
    raise BattgenError(f"{path}: no such file or folder")


def _deduplicated(schema: Schema) -> Schema:
    """Drop repeats of one definition (a referenced type parsed twice); reject clashing ones."""
    seen: dict[str, object] = {}
    messages = []
    for msg in schema.messages:
        prior = seen.get(msg.qualified_name)
        if prior is None:
            seen[msg.qualified_name] = msg
            messages.append(msg)
        elif prior != msg:
            loc = msg.location
            raise SchemaError(loc.file, loc.line, f"{msg.qualified_name} is defined twice with different contents")
    enums: dict[str, EnumDef] = {}
    for enum_def in schema.enums:
        enums.setdefault(enum_def.name, enum_def)
    return Schema(
        messages=tuple(sorted(messages, key=lambda m: m.qualified_name)),
        enums=tuple(sorted(enums.values(), key=lambda e: e.name)),
        sources=tuple(dict.fromkeys(schema.sources)),
        mappings=schema.mappings,
        rules=schema.rules,
        warnings=tuple(dict.fromkeys(schema.warnings)),
    )
