"""Pick the frontend for each input and merge what they produce into one Schema.

Like a compiler, a load reports every error in one run: each format folder and each path given is
parsed even when an earlier one failed, and the errors of all of them are raised together as one
:class:`~codegen.errors.ErrorList` (the frontends collect theirs per file and line the same way).
Mappings and rules are checked only when the formats they refer to parsed cleanly, since a
message missing because its file is broken would otherwise be reported again from every mapping.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Protocol

from ..errors import BattgenError, ErrorList, SchemaError
from ..ir import EnumDef, Schema
from . import devicetree, dsdl, mavlink, pdef, rules, uorb


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
}

# converter mappings between the formats (schemas/mappings/*.yaml), parsed after the formats
MAPPINGS_DIR = "mappings"
# cross-field rules the validators compile (schemas/rules/*.yaml), also read after the formats
RULES_DIR = "rules"

EXTENSION_FORMATS: dict[str, str] = {
    ".msg": "uorb",
    ".uavcan": "dronecan",
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


def load_schema_dir(root: Path) -> Schema:
    """A folder laid out as uorb/, dronecan/, devicetree/, mavlink/ (any subset)."""
    schema = Schema()
    errors: list[BattgenError] = []
    for fmt in FORMAT_FRONTENDS:
        sub = root / fmt
        if sub.is_dir():
            try:
                part: Schema = frontend(fmt).parse_dir(sub)
            except BattgenError as error:
                errors.append(error)
                continue
            schema = schema.merged(part)
    ErrorList.raise_if_any(errors)
    if (root / MAPPINGS_DIR).is_dir():
        # after the formats, so every reference to a message or field can be checked
        from . import mappings

        schema = schema.merged(mappings.parse_dir(root / MAPPINGS_DIR, schema=schema))
    if (root / RULES_DIR).is_dir():
        schema = schema.merged(Schema(rules=rules.load_rules_dir(root / RULES_DIR)))
        rules.check_rules(schema)  # after the formats: every rule must bind to the messages it names
    return schema


def load(paths: Iterable[Path]) -> Schema:
    """Parse schema folders and single files (format from the extension) into one Schema; the
    errors of every path are raised together."""
    schema = Schema()
    errors: list[BattgenError] = []
    for path in paths:
        try:
            part = _load_path(path)
        except BattgenError as error:
            errors.append(error)
            continue
        schema = schema.merged(part)
    ErrorList.raise_if_any(errors)
    return _deduplicated(schema)


def _load_path(path: Path) -> Schema:
    if path.is_dir():
        if not is_schema_dir(path) and any(p.is_file() for p in path.glob("*.msg")):
            return frontend("uorb").parse_dir(path)  # a folder of .msg files, as PX4's own msg/
        if not is_schema_dir(path):
            expected = ", ".join(f"{f}/" for f in FORMAT_FRONTENDS)
            raise BattgenError(
                f"{path}: not a schema folder (expected sub-folders {expected}, or a folder of .msg files)"
            )
        return load_schema_dir(path)
    if path.is_file():
        return frontend(format_of_file(path)).parse_file(path)
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
