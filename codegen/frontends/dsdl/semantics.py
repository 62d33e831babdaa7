"""What DSDL comments and constant names say about fields: docs, units, ranges, enums, sentinels.

Rules (generic, applied to every definition):

* Docs: a field's or constant's doc is the comment block directly above it (no blank line in
  between) followed by its trailing comment. The file's leading comment block is the message doc.
* Units: a trailing comment that starts with ``[...]`` names the unit (``# [Volt]``), resolved
  through :func:`codegen.ir.units.lookup`, else kept opaque; ``unit_text`` keeps the spelling. A
  bracket holding two numbers (``# [-1, 1]``) is a range instead. The tag is removed from the doc.
  DSDL files write degrees Celsius as ``[C]`` (no DroneCAN type carries coulombs), so ``C`` means
  Celsius here.
* Enums: integer constants whose names share a first ``WORD_`` form a group when there are two
  or more; the group prefix is extended to the longest ``_``-delimited prefix all members share
  (``STATUS_FLAG_``). The group is the enum ``<message>.<STEM>``; fields whose upper-cased name
  starts with the stem (``status_flags`` for ``STATUS_FLAG``) draw on it. It is a BITMASK when all
  values are distinct powers of two and such a field exists, else VALUE. Constants that all end in
  ``_UNKNOWN`` are the sentinels of as many fields (below), not an enum.
* Sentinels: a constant ``<X>_UNKNOWN`` marks the "unknown" value of the only field whose
  upper-cased name starts with ``X`` (of several, the one whose name the others extend); a bare ``UNKNOWN``
  does so for a structure's only field.
  Where DSDL has no constant for it (float fields that are NaN when unknown), a trailing comment
  may carry the uORB-style tag ``[@invalid NaN]`` (or a number); comments never change the wire
  format or the signature, so this stays compatible with every other DSDL tool.
"""

from __future__ import annotations

import re

from ...ir import EnumDef, EnumEntry, EnumKind, Location, Range, Sentinel, Unit, units
from .definitions import ArrayT, ConstDef, FieldDef

_TAG_RE = re.compile(r"\[([^\]]*)\]\s*:?\s*(.*)\Z", re.DOTALL)
_NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_RANGE_RE = re.compile(rf"\s*({_NUMBER})\s*,\s*({_NUMBER})\s*\Z")
_DSDL_SPELLINGS = {"C": "Celsius"}


def join_doc(*parts: str) -> str:
    return "\n".join(p for p in parts if p)


def split_tag(trailing: str) -> tuple[str | None, Range | None, str]:
    """A trailing comment -> (unit text, range, the rest of the comment)."""
    match = _TAG_RE.match(trailing)
    if not match:
        return None, None, trailing
    tag, rest = match.group(1).strip(), match.group(2).strip()
    if tag.startswith("@"):  # an annotation such as [@invalid NaN], not a unit
        return None, None, trailing
    numbers = _RANGE_RE.match(tag)
    if numbers:
        low, high = (_number(numbers.group(i)) for i in (1, 2))
        return None, Range(minimum=low, maximum=high), rest
    if not tag:
        return None, None, trailing
    return tag, None, rest


_INVALID_RE = re.compile(r"\[@invalid\s+([^\]]+)\]\s*")


def split_invalid(comment: str, is_float: bool) -> tuple[Sentinel | None, str | None, str]:
    """A ``[@invalid X]`` tag in a comment -> (sentinel, error text, the comment without it)."""
    match = _INVALID_RE.search(comment)
    if not match:
        return None, None, comment
    rest = (comment[: match.start()] + comment[match.end() :]).strip()
    text = match.group(1).strip()
    if text.lower() == "nan":
        if not is_float:
            return None, f"expected [@invalid NaN] only on a float field, got {text!r}", rest
        return Sentinel(float("nan"), text), None, rest
    try:
        value = _number(text)
    except ValueError:
        return None, f"expected [@invalid NaN] or [@invalid <number>], got {text!r}", rest
    return Sentinel(value, text), None, rest


def _number(text: str) -> int | float:
    try:
        return int(text)
    except ValueError:
        return float(text)


def resolve_unit(text: str) -> Unit:
    return units.lookup(_DSDL_SPELLINGS.get(text, text)) or units.opaque(text)


def _stem_matches(field_name: str | None, stem: str) -> bool:
    return bool(field_name) and str(field_name).upper().startswith(stem)


def group_enums(
    message_qn: str, constants: tuple[ConstDef, ...], fields: tuple[FieldDef, ...], file: str
) -> tuple[tuple[EnumDef, ...], dict[str, tuple[str, ...]]]:
    """Enum groups of a structure, and for each field name the enums it draws on."""
    groups: dict[str, list[ConstDef]] = {}
    for c in constants:
        head, sep, tail = c.name.partition("_")
        if sep and tail and c.type.kind != "float":
            groups.setdefault(head, []).append(c)
    enums: list[EnumDef] = []
    links: dict[str, list[str]] = {}
    for members in groups.values():
        if len(members) < 2 or all(m.name.endswith("_UNKNOWN") for m in members):
            continue  # STATE_OF_HEALTH_UNKNOWN and STATE_OF_CHARGE_UNKNOWN: two fields' sentinels, not an enum
        stem = _common_stem([m.name.split("_") for m in members])
        name = f"{message_qn}.{stem}"
        linked = [f.name for f in fields if f.name and _stem_matches(f.name, stem)]
        values = [int(m.value) for m in members]
        powers = all(v > 0 and v & (v - 1) == 0 for v in values) and len(set(values)) == len(values)
        kind = EnumKind.BITMASK if powers and linked else EnumKind.VALUE
        entries = tuple(EnumEntry(m.name, int(m.value), m.trailing, Location(file, m.line)) for m in members)
        enums.append(EnumDef(name, kind, entries, members[0].above, Location(file, members[0].line)))
        for fname in linked:
            links.setdefault(fname, []).append(name)
    return tuple(enums), {k: tuple(v) for k, v in links.items()}


def _common_stem(names: list[list[str]]) -> str:
    """Longest shared token prefix that leaves every member at least one token of its own."""
    stem = [names[0][0]]
    while True:
        n = len(stem)
        candidates = {tuple(t[: n + 1]) for t in names if len(t) > n + 1}
        if len(candidates) != 1 or any(len(t) <= n + 1 for t in names):
            return "_".join(stem)
        stem = list(next(iter(candidates)))


def sentinels(constants: tuple[ConstDef, ...], fields: tuple[FieldDef, ...]) -> dict[str, Sentinel]:
    """For each field name, the constant that marks its value as unknown."""
    named = [f for f in fields if f.name]
    found: dict[str, Sentinel] = {}
    for c in constants:
        if c.name == "UNKNOWN":
            matches = named if len(named) == 1 else []
        elif c.name.endswith("_UNKNOWN") and len(c.name) > len("_UNKNOWN"):
            prefix = c.name[: -len("_UNKNOWN")]
            matches = [f for f in named if _stem_matches(f.name, prefix)]
            # STATE_OF_CHARGE_UNKNOWN matches state_of_charge_pct and state_of_charge_pct_stdev: the field the
            # others extend (their name is its name and a suffix) is the quantity the constant speaks of
            base = [f for f in matches if all(g is f or str(g.name).startswith(f"{f.name}_") for g in matches)]
            matches = base if len(base) == 1 else matches
        else:
            continue
        if len(matches) == 1 and matches[0].name not in found:
            f = matches[0]
            found[str(f.name)] = Sentinel(c.value, c.name, per_element=isinstance(f.type, ArrayT))
    return found
