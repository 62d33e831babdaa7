"""One <param> of apm.pdef.xml -> an IR Field, with its enum when it has Values or a Bitmask.

A vehicle's ``ArduCopter:NAME`` loses its prefix; names fit a MAVLink PARAM_VALUE param_id.
Values and Bitmask come as child elements (``<values><value code="0">None</value>``) or as a
field (``<field name="Values">0:None,1:Hold</field>``); their labels become entry names
``<SHORT>_<LABEL>``. Units, Range, Type, Default, Values and Bitmask become IR facts; the other
fields (Increment, User, RebootRequired...) and the humanName/user attributes stay annotations.
"""

from __future__ import annotations

import re

from ...errors import SchemaError
from ...ir import Constant, EnumDef, EnumEntry, EnumKind, Field, Location, units
from .tree import Element
from .values import INT, Entry, parameter_type, parse_default, parse_range

MAX_NAME = 16  # a MAVLink PARAM_VALUE param_id holds 16 characters
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
# fields turned into IR facts rather than annotations
_STRUCTURAL = frozenset({"Type", "Units", "Range", "Default", "Values", "Bitmask"})


def parameter(node: Element, qualified: str, prefix: str) -> tuple[Field, EnumDef | None, list[Constant]]:
    """The Field of one <param> of group ``qualified``, its enum (if any) and the enum's members as constants."""
    raw = node.attrs.get("name")
    if raw is None:
        raise node.error('expected a "name" attribute on <param>')
    name = raw.split(":", 1)[1] if ":" in raw else raw  # ArduCopter:FRAME_CLASS -> FRAME_CLASS
    if not _NAME.fullmatch(name) or len(name) > MAX_NAME:
        raise node.error(f"expected a parameter name of 1 to {MAX_NAME} letters, digits and _, got {raw!r}")
    fields: dict[str, Element] = {}
    values: Element | None = None
    bits: Element | None = None
    for child in node.children:
        if child.tag == "field":
            key = child.attrs.get("name")
            if not key:
                raise child.error('expected a "name" attribute on <field>')
            if key in fields:
                raise child.error(f"expected one <field name={key!r}> in {name} (also line {fields[key].line})")
            fields[key] = child
        elif child.tag == "values":
            values = child
        elif child.tag == "bitmask":
            bits = child
        else:
            raise child.error(f"expected <field>, <values> or <bitmask> in <param>, got <{child.tag}>")

    value_entries = _entries(values, "value") if values is not None else None
    if value_entries is None and "Values" in fields:
        value_entries = _pairs(fields["Values"], "Values")
    bit_entries = _entries(bits, "bit") if bits is not None else None
    if bit_entries is None and "Bitmask" in fields:
        bit_entries = _pairs(fields["Bitmask"], "Bitmask")
    if value_entries is not None and bit_entries is not None:
        raise node.error(f"expected Values or a Bitmask on {name}, not both")

    rng = parse_range(fields["Range"]) if "Range" in fields else None
    ptype = parameter_type(fields, node, name, rng, value_entries, bit_entries)
    default = parse_default(fields["Default"], ptype, rng, name) if "Default" in fields else None
    unit = unit_text = None
    if "Units" in fields and fields["Units"].text:
        unit_text = fields["Units"].text
        unit = units.lookup(unit_text) or units.opaque(unit_text)

    short = name[len(prefix) :] if prefix and name.startswith(prefix) and len(name) > len(prefix) else name
    enum_name = f"{qualified}.{short}"
    enum: EnumDef | None = None
    members: list[Constant] = []
    if value_entries is not None:
        enum = _enum(enum_name, short, EnumKind.VALUE, value_entries, node)
    elif bit_entries is not None:
        for code, _, where in bit_entries:
            if not 0 <= code < ptype.bits:
                raise SchemaError(
                    node.file, where, f"expected a bit number from 0 to {ptype.bits - 1} in {name}, got {code}"
                )
        masks = [Entry(1 << code, label, where) for code, label, where in bit_entries]
        enum = _enum(enum_name, short, EnumKind.BITMASK, masks, node)
    if enum is not None:
        members = [Constant(e.name, ptype, e.value, e.doc, e.location) for e in enum.entries]

    annotations: list[tuple[str, str]] = []
    for attr in ("humanName", "user"):
        if attr in node.attrs:
            annotations.append((attr, node.attrs[attr]))
    for key, child in fields.items():
        if key not in _STRUCTURAL or (key in ("Values", "Bitmask") and enum is None):
            annotations.append((key, child.text))
    f = Field(
        name=name,
        type=ptype,
        location=node.location(),
        doc=node.attrs.get("documentation", "").strip(),
        unit=unit,
        unit_text=unit_text,
        range=rng,
        enums=(enum.name,) if enum is not None else (),
        default=default,
        annotations=tuple(annotations),
    )
    return f, enum, members


def _entries(node: Element, tag: str) -> list[Entry]:
    """``<values><value code="0">None</value>...`` (or ``<bitmask><bit code=...>``)."""
    out = []
    for child in node.children:
        if child.tag != tag:
            raise child.error(f"expected <{tag}> in <{node.tag}>, got <{child.tag}>")
        code = child.attrs.get("code", "").strip()
        if not INT.fullmatch(code):
            raise child.error(f'expected an integer code="..." on <{tag}>, got {code!r}')
        out.append(Entry(int(code), child.text, child.line))
    return out


def _pairs(node: Element, what: str) -> list[Entry]:
    """``0:None,1:Hold`` as written in a <field name="Values"> / "Bitmask"."""
    out = []
    for part in node.text.split(","):
        code, sep, label = part.partition(":")
        if not sep or not INT.fullmatch(code.strip()):
            raise node.error(f"expected {what} as code:label pairs separated by commas, got {part.strip()!r}")
        out.append(Entry(int(code), label.strip(), node.line))
    return out


def _enum(name: str, short: str, kind: EnumKind, items: list[Entry], node: Element) -> EnumDef:
    entries: list[EnumEntry] = []
    seen_codes: dict[int, int] = {}
    used: set[str] = set()
    for code, label, where in items:
        if code in seen_codes:
            raise SchemaError(
                node.file,
                where,
                f"expected each code once in {short}: {code} is also at line {seen_codes[code]}",
            )
        seen_codes[code] = where
        stem = re.sub(r"[^0-9A-Za-z]+", "_", label).strip("_").upper() or str(code)
        entry_name = f"{short}_{stem}"
        while entry_name in used:
            entry_name += f"_{code}"
        used.add(entry_name)
        doc = label if kind is EnumKind.VALUE else f"{label} (bit {code.bit_length() - 1})"
        entries.append(EnumEntry(entry_name, code, doc, Location(node.file, where)))
    return EnumDef(name=name, kind=kind, entries=tuple(entries), location=node.location())
