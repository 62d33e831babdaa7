"""uORB enums: a naming convention, not a declaration.

A field tagged ``[@enum WARNING]`` takes the message's constants named ``WARNING_*``. The group
is a bit-index enum when the field is documented as a bitmask/flags field and the values are
0..n-1, a bitmask enum when they are distinct powers of two, else a plain value enum. A trailing
``*_COUNT`` constant one past the others is a counter, not a member (it stays a constant).
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from ...errors import SchemaError
from ...ir import Constant, EnumDef, EnumEntry, EnumKind, Field

_BITMASK_DOC = re.compile(r"\b(bitmask|bitfield|flags)\b", re.I)


def build_enums(
    qualified_name: str, fields: Sequence[Field], constants: Sequence[Constant], file: str
) -> tuple[EnumDef, ...]:
    owners: dict[str, Field] = {}  # enum prefix -> first field naming it
    for f in fields:
        for qualified in f.enums:
            owners.setdefault(qualified.rsplit(".", 1)[-1], f)
    members: dict[str, list[Constant]] = {prefix: [] for prefix in owners}
    for c in constants:
        # the longest matching prefix wins, so FAULT and FAULT_MODE can coexist
        matching = [p for p in owners if c.name.startswith(p + "_")]
        if matching:
            members[max(matching, key=len)].append(c)
    return tuple(_enum(f"{qualified_name}.{prefix}", owner, members[prefix], file) for prefix, owner in owners.items())


def _enum(name: str, owner: Field, constants: list[Constant], file: str) -> EnumDef:
    line = owner.location.line
    prefix = name.rsplit(".", 1)[-1]
    if not constants:
        raise SchemaError(file, line, f"expected constants named {prefix}_* in this message for '[@enum {prefix}]'")
    for c in constants:
        if isinstance(c.value, float | str):
            where = c.location.line if c.location else line
            raise SchemaError(file, where, f"expected an integer constant in enum {prefix}, got {c.name} = {c.value!r}")
    values = [int(c.value) for c in constants]
    others = [v for c, v in zip(constants, values, strict=True) if not c.name.endswith("_COUNT")]
    entries = [
        EnumEntry(c.name, v, c.doc, c.location)
        for c, v in zip(constants, values, strict=True)
        if not (c.name.endswith("_COUNT") and others and v > max(others))
    ]
    return EnumDef(
        name=name, kind=_kind(owner, [e.value for e in entries]), entries=tuple(entries), location=owner.location
    )


def _kind(owner: Field, values: list[int]) -> EnumKind:
    if not _BITMASK_DOC.search(owner.doc):
        return EnumKind.VALUE
    if sorted(values) == list(range(len(values))):
        return EnumKind.BIT_INDEX
    masks = [v for v in values if v != 0]  # a NONE = 0 entry may sit beside the bits
    if len(set(masks)) == len(masks) and all(v > 0 and v & (v - 1) == 0 for v in masks):
        return EnumKind.BITMASK
    return EnumKind.VALUE
