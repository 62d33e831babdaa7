"""What Cyphal definitions say beyond their layout: units, the NaN and zero sentinels, enums, source lines.

Rules (generic, applied to every definition):

* Units: a field of a type in ``uavcan.si`` (``unit`` and ``sample``) or ``uavcan.time`` is named after its
  unit (``float32 volt``, ``float32 kelvin``, ``uint56 microsecond``), so the name is looked up in the unit
  registry (an unknown one is kept opaque). A field whose type is such a one-value type (a ``Scalar``)
  carries that unit too, so ``Status.available_charge`` reads as coulombs. A doc that starts with a
  bracket (``# [volt]``, ``# [percent]``) names the unit of a field of any other type; a name ending in
  ``_pct`` is percent.
* Sentinels: UDRAL's rule is that a float quantity is NaN when unknown (its services say so and the ESC
  service states it for every reported quantity), so the float fields of the ``uavcan.si`` types carry
  ``NaN`` as their "unknown" value. A constant ``UNKNOWN`` of a one-field type marks that field's unknown
  value (``SynchronizedTimestamp``: zero).
* Enums: the integer constants of a one-field type of that field's type enumerate its values
  (``Error.0.1``: ``NONE``, ``BAD_BATTERY``, ...; ``Health.1.0``), as the regulated types use them; a
  constant named ``MAX_*`` or ``UNKNOWN`` is a bound or a sentinel, not a member.
* Source lines: pydsdl keeps no line per attribute, so each is found in the file text in declaration order.
"""

from __future__ import annotations

import re

import pydsdl

from ...ir import EnumDef, EnumEntry, EnumKind, Location, Sentinel, Unit, units

_UNIT_NAMESPACES = ("uavcan.si.", "uavcan.time.")
_TAG_RE = re.compile(r"\A\[([^\]\n]+)\]\s*")
UDRAL_PREFIX = "reg.udral."
DRONE_PREFIX = "reg.drone."  # UDRAL's former name, still in devices' firmware (NXP's BMS)


def canonical_name(full_name: str) -> str:
    """``reg.drone.X`` read as ``reg.udral.X``; every other name as it is."""
    if full_name.startswith(DRONE_PREFIX):
        return UDRAL_PREFIX + full_name[len(DRONE_PREFIX) :]
    return full_name


def names_units(owner: str) -> bool:
    """Whether the fields of type ``owner`` are named after their units."""
    return canonical_name(owner).startswith(_UNIT_NAMESPACES)


def unit_of_name(name: str) -> Unit:
    return units.lookup(name) or units.opaque(name)


def split_doc_unit(doc: str) -> tuple[str | None, str]:
    """A doc's leading ``[unit]`` tag -> (its text, the doc without it)."""
    match = _TAG_RE.match(doc)
    if match is None:
        return None, doc
    return match.group(1).strip(), doc[match.end() :]


def field_unit(owner: str, field: pydsdl.Field, doc: str) -> tuple[Unit | None, str | None, str]:
    """(unit, the unit's spelling, doc without its tag) of a field of a primitive or array type."""
    tag, rest = split_doc_unit(doc)
    if tag is not None:
        return unit_of_name(tag), tag, rest
    if names_units(owner) and not isinstance(field, pydsdl.PaddingField):
        return unit_of_name(field.name), field.name, doc
    if field.name.endswith("_pct"):
        return units.lookup("percent"), "percent", doc
    return None, None, doc


def nan_when_unknown(owner: str, element: pydsdl.SerializableType) -> bool:
    return isinstance(element, pydsdl.FloatType) and canonical_name(owner).startswith("uavcan.si.")


def value_fields(t: pydsdl.CompositeType) -> list[pydsdl.Field]:
    return [f for f in t.fields if not isinstance(f, pydsdl.PaddingField)]


def unknown_sentinel(t: pydsdl.CompositeType, field: pydsdl.Field) -> Sentinel | None:
    """The ``UNKNOWN`` constant of a one-field type, as that field's sentinel."""
    if value_fields(t) != [field]:
        return None
    for c in t.constants:
        if c.name == "UNKNOWN":
            return Sentinel(_number(c.value), c.name)
    return None


def enum_of(qualified: str, t: pydsdl.CompositeType, file: str, lines: dict[str, int]) -> EnumDef | None:
    """The values of a one-field type's field, from its constants (the rules above)."""
    fields = value_fields(t)
    if len(fields) != 1 or not isinstance(fields[0].data_type, pydsdl.IntegerType):
        return None
    kind = fields[0].data_type
    members = [
        c
        for c in t.constants
        if type(c.data_type) is type(kind)  # saturated or truncated alike (Readiness: truncated uint2)
        and c.data_type.bit_length == kind.bit_length
        and c.name != "UNKNOWN"
        and not c.name.startswith("MAX_")
    ]
    if len(members) < 2:
        return None
    entries = tuple(
        EnumEntry(c.name, int(_number(c.value)), c.doc, Location(file, lines.get("constant " + c.name, 0)))
        for c in members
    )
    return EnumDef(f"{qualified}.{fields[0].name.upper()}", EnumKind.VALUE, entries, "", entries[0].location)


def _number(value: pydsdl.Any) -> int | float:
    """A constant's value as a Python number (pydsdl keeps rationals and booleans)."""
    if isinstance(value, pydsdl.Boolean):
        return int(value.native_value)
    if isinstance(value, pydsdl.Rational):
        number = value.native_value
        return int(number) if number.denominator == 1 else float(number)
    return 0


def constant_value(value: pydsdl.Any) -> int | float | bool | str:
    if isinstance(value, pydsdl.Boolean):
        return bool(value.native_value)
    if isinstance(value, pydsdl.String):
        return str(value.native_value)
    return _number(value)


_COMMENT = re.compile(r"#.*")


def attribute_lines(text: str, sections: list[list[pydsdl.Attribute]]) -> list[dict[str, int]]:
    """For each section (a service has two, split by ``---``), the 1-based line of each attribute,
    keyed ``field NAME`` / ``constant NAME`` / ``void INDEX``, and ``section`` for its first line."""
    out: list[dict[str, int]] = []
    lines = text.splitlines()
    at = 0
    for attributes in sections:
        found: dict[str, int] = {"section": at + 1}
        voids = 0
        for attribute in attributes:
            if isinstance(attribute, pydsdl.PaddingField):
                key, pattern = f"void {voids}", re.compile(r"^\s*void\d+\s*$")
                voids += 1
            elif isinstance(attribute, pydsdl.Constant):
                key, pattern = "constant " + attribute.name, re.compile(rf"\b{re.escape(attribute.name)}\s*=")
            else:
                key, pattern = "field " + attribute.name, re.compile(rf"\b{re.escape(attribute.name)}\s*$")
            for index in range(at, len(lines)):
                if lines[index].strip() == "---":
                    break
                if pattern.search(_COMMENT.sub("", lines[index])):
                    found[key] = index + 1
                    at = index + 1
                    break
        out.append(found)
        while at < len(lines) and lines[at].strip() != "---":
            at += 1
        at += 1
    return out
