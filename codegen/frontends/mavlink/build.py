"""Translate pymavlink's parse results (plus our pre-scan's lines and extra attributes) into IR.

Choices worth knowing:
- Enums are dialect-level (Schema.enums). An enum defined in several files (a dialect extending
  MAV_CMD) is merged: location/doc from the first definition in include order (included files
  come before their includer), entries sorted by value as pymavlink does; no *_ENUM_END entry.
- deprecated / superseded / wip markers are kept as a bracketed note at the end of the doc of
  the message, enum or entry they mark. Command <param>s have no place in the IR and are dropped.
- Sentinel.text is the ``invalid`` attribute verbatim, brackets included.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import ErrorCollector, SchemaError
from ...ir import (
    ArrayType,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    FieldType,
    Location,
    MavlinkInfo,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
    StringType,
    units,
)
from . import layout, values
from .scan import MAVLINK_VERSION_TYPE, ScannedField, ScannedFile

PREFIX = "mavlink."
MAX_PAYLOAD = 255
_ANNOTATED = ("instance", "display", "print_format", "multiplier", "increment")
_PRIMITIVES = {
    "int8_t": (PrimitiveKind.INT, 8),
    "int16_t": (PrimitiveKind.INT, 16),
    "int32_t": (PrimitiveKind.INT, 32),
    "int64_t": (PrimitiveKind.INT, 64),
    "uint8_t": (PrimitiveKind.UINT, 8),
    "uint16_t": (PrimitiveKind.UINT, 16),
    "uint32_t": (PrimitiveKind.UINT, 32),
    "uint64_t": (PrimitiveKind.UINT, 64),
    "float": (PrimitiveKind.FLOAT, 32),
    "double": (PrimitiveKind.FLOAT, 64),
    "char": (PrimitiveKind.CHAR, 8),
}


@dataclass
class LoadedFile:
    """One XML file: where it is, our pre-scan, and pymavlink's MAVXML for it."""

    path: Path
    display: str
    scan: ScannedFile
    mavxml: Any


def _paired(display: str, ours: Sequence[Any], theirs: Sequence[Any]) -> Iterable[tuple[Any, Any]]:
    # Both walk the same element paths in document order, so they pair up one to one.
    if [o.name for o in ours] != [t.name for t in theirs]:
        line = ours[0].line if ours else 1
        raise SchemaError(display, line, "expected pymavlink to read the same definitions as the pre-scan")
    return zip(ours, theirs, strict=True)


def _note(kind: str, marker: Any) -> str:
    since, replaced_by, explanation = marker
    text = f"[{kind} since {since}" + (f"; replaced by {replaced_by}" if replaced_by else "")
    explanation = " ".join(explanation.split())
    return text + (f": {explanation}]" if explanation else "]")


def _doc(text: str, theirs: Any, superseded: tuple[str, str] | None) -> str:
    parts = [" ".join(text.split())]
    if theirs.deprecated is not None:
        d = theirs.deprecated
        parts.append(_note("deprecated", (d.since, d.replaced_by, d.explanation)))
    if superseded is not None:
        parts.append(_note("superseded", (*superseded, "")))
    if getattr(theirs, "wip", False):
        parts.append("[work in progress]")
    return " ".join(p for p in parts if p)


@dataclass
class _EnumParts:
    location: Location
    doc: str
    bitmask: bool
    entries: list[EnumEntry]


def _merge_enums(files: Sequence[LoadedFile]) -> dict[str, _EnumParts]:
    merged: dict[str, _EnumParts] = {}
    for lf in files:
        for ours, theirs in _paired(lf.display, lf.scan.enums, lf.mavxml.enum):
            doc = _doc(theirs.description, theirs, ours.superseded)
            parts = merged.setdefault(ours.name, _EnumParts(Location(lf.display, ours.line), doc, False, []))
            parts.doc = parts.doc or doc
            parts.bitmask = parts.bitmask or ours.bitmask
            seen = {e.name: e for e in parts.entries} | {str(e.value): e for e in parts.entries}
            for entry, their_entry in _paired(lf.display, ours.entries, theirs.entry):
                clash = seen.get(entry.name) or seen.get(str(entry.value))
                if clash is not None:
                    raise SchemaError(
                        lf.display,
                        entry.line,
                        f"expected unique entry names and values in enum {ours.name}; "
                        f"{entry.name} = {entry.value} clashes with {clash.name} = {clash.value} at {clash.location}",
                    )
                built = EnumEntry(
                    entry.name,
                    entry.value,
                    _doc(their_entry.description, their_entry, entry.superseded),
                    Location(lf.display, entry.line),
                )
                parts.entries.append(built)
                seen[entry.name] = seen[str(entry.value)] = built
    for parts in merged.values():
        parts.entries.sort(key=lambda e: e.value)
    return merged


def _field_type(theirs: Any) -> FieldType:
    kind, bits = _PRIMITIVES[theirs.type]
    if theirs.array_length and kind is PrimitiveKind.CHAR:
        return StringType(capacity=theirs.array_length)
    element = PrimitiveType(kind, bits)
    if theirs.array_length:
        return ArrayType(element, theirs.array_length, dynamic=False)
    return element


def _element(ftype: FieldType) -> PrimitiveType:
    if isinstance(ftype, StringType):
        return PrimitiveType(PrimitiveKind.CHAR, 8)
    if isinstance(ftype, ArrayType) and isinstance(ftype.element, PrimitiveType):
        return ftype.element
    assert isinstance(ftype, PrimitiveType)
    return ftype


def _sentinel(text: str, ftype: FieldType, enum: _EnumParts | None, where: Location) -> Sentinel:
    names = {e.name: e.value for e in enum.entries} if enum is not None else {}
    found = values.sentinel(text, names)
    if found is None:
        raise SchemaError(where.file, where.line, f"expected invalid= to be {values.SENTINEL_FORMS}, got {text!r}")
    element = _element(ftype)
    if (found.per_element or found.first_decides) and isinstance(ftype, PrimitiveType):
        raise SchemaError(where.file, where.line, f"expected a bracketed invalid={text!r} only on an array field")
    markers = [m for m in found.elements if m is not None] or [found.value]
    if not all(values.fits(m, element) for m in markers):
        raise SchemaError(where.file, where.line, f"expected an invalid value that fits {element.name}, got {text!r}")
    length = ftype.capacity if isinstance(ftype, ArrayType | StringType) else 1
    if length is not None and len(found.elements) > length:
        raise SchemaError(
            where.file, where.line, f"expected at most {length} positions in invalid={text!r}, one per array element"
        )
    if element.kind is not PrimitiveKind.FLOAT:  # 1.0 written for an integer field is the integer 1
        positions = [None if m is None else int(m) for m in found.elements]
        found = Sentinel(int(found.value), found.text, found.per_element, tuple(positions), found.first_decides)
    return found


def _number(text: str, attr: str, where: Location, *, nan: bool) -> int | float:
    value = values.number(text)
    if value is None or (not nan and isinstance(value, float) and math.isnan(value)):
        raise SchemaError(where.file, where.line, f"expected a number as {attr}=, got {text!r}")
    return value


def _field(lf: LoadedFile, ours: ScannedField, theirs: Any, enums: dict[str, _EnumParts]) -> Field:
    where = Location(lf.display, ours.line)
    ftype = _field_type(theirs)
    enum = None
    if theirs.enum:
        enum = enums.get(theirs.enum)
        if enum is None:
            raise SchemaError(
                where.file,
                where.line,
                f"expected enum {theirs.enum} to be defined in this dialect or a file it includes",
            )
    unit = unit_text = None
    if theirs.units:
        unit_text = theirs.units[1:-1]  # pymavlink wraps units in brackets
        unit = units.lookup(unit_text) or units.opaque(unit_text)
    attrs = ours.attrs
    value_range = None
    if "minValue" in attrs or "maxValue" in attrs:
        value_range = Range(
            minimum=_number(attrs["minValue"], "minValue", where, nan=False) if "minValue" in attrs else None,
            maximum=_number(attrs["maxValue"], "maxValue", where, nan=False) if "maxValue" in attrs else None,
        )
    annotations = tuple((a, attrs[a]) for a in _ANNOTATED if a in attrs)
    const = None
    if ours.type_text == MAVLINK_VERSION_TYPE:
        annotations += (("type", MAVLINK_VERSION_TYPE),)
        const = int(theirs.const_value)
    return Field(
        name=ours.name,
        type=ftype,
        location=where,
        doc=" ".join(theirs.description.split()),
        unit=unit,
        unit_text=unit_text,
        range=value_range,
        invalid=_sentinel(theirs.invalid, ftype, enum, where) if theirs.invalid else None,
        enums=(PREFIX + theirs.enum,) if theirs.enum else (),
        extension=ours.extension,
        const=const,
        default=_number(attrs["default"], "default", where, nan=True) if "default" in attrs else None,
        annotations=annotations,
    )


def _message(lf: LoadedFile, ours: Any, theirs: Any, enums: dict[str, _EnumParts]) -> Message:
    fields: list[Field] = []
    for sf, mf in _paired(lf.display, ours.fields, theirs.fields):
        if any(f.name == sf.name for f in fields):
            raise SchemaError(lf.display, sf.line, f"expected unique field names in {ours.name}; {sf.name} repeats")
        fields.append(_field(lf, sf, mf, enums))
    base_length, max_length = layout.lengths(fields)
    if max_length > MAX_PAYLOAD:
        raise SchemaError(
            lf.display, ours.line, f"expected at most {MAX_PAYLOAD} payload bytes in {ours.name}, got {max_length}"
        )
    info = MavlinkInfo(
        msg_id=ours.msg_id,
        crc_extra=layout.crc_extra(ours.name, fields),
        dialect=lf.path.stem,
        wire_order=tuple(f.name for f in layout.wire_order(fields)),
        base_length=base_length,
        max_length=max_length,
    )
    return Message(
        name=ours.name,
        qualified_name=PREFIX + ours.name,
        format=SourceFormat.MAVLINK,
        location=Location(lf.display, ours.line),
        doc=_doc(theirs.description, theirs, ours.superseded),
        fields=tuple(fields),
        mavlink=info,
    )


def _enum_kind(parts: _EnumParts, name: str, bitmask_refs: set[str]) -> EnumKind:
    if parts.bitmask:
        return EnumKind.BITMASK
    codes = [e.value for e in parts.entries]
    powers = bool(codes) and all(v > 0 and v & (v - 1) == 0 for v in codes) and len(set(codes)) == len(codes)
    return EnumKind.BITMASK if powers and name in bitmask_refs else EnumKind.VALUE


def build(files: Sequence[LoadedFile]) -> Schema:
    enums = _merge_enums(files)
    messages: dict[str, Message] = {}
    by_id: dict[int, Message] = {}
    found = ErrorCollector()  # every bad message of every file in one report
    for lf in files:
        pairs: list[tuple[Any, Any]] = []
        with found.step():
            pairs = list(_paired(lf.display, lf.scan.messages, lf.mavxml.message))
        for ours, theirs in pairs:
            with found.step():
                clash = messages.get(PREFIX + ours.name) or by_id.get(ours.msg_id)
                if clash is not None:
                    raise SchemaError(
                        lf.display,
                        ours.line,
                        f"expected unique message names and ids; {ours.name} "
                        f"(id {ours.msg_id}) clashes with {clash.name} at {clash.location}",
                    )
                message = _message(lf, ours, theirs, enums)
                messages[message.qualified_name] = by_id[ours.msg_id] = message
    found.raise_if_any()
    bitmask_refs = {
        f.enums[0][len(PREFIX) :]
        for m in messages.values()
        for f in m.fields
        if f.enums and ("display", "bitmask") in f.annotations
    }
    enum_defs = [
        EnumDef(PREFIX + name, _enum_kind(p, name, bitmask_refs), tuple(p.entries), p.doc, p.location)
        for name, p in enums.items()
    ]
    return Schema(
        messages=tuple(sorted(messages.values(), key=lambda m: m.qualified_name)),
        enums=tuple(sorted(enum_defs, key=lambda e: e.name)),
        sources=tuple(lf.display for lf in files),
    )
