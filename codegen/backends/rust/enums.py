"""Enum groups of the IR as Rust types: a value enum as a fieldless ``enum`` with ``from_value``,
a bitmask (masks or bit positions) as a newtype of its bits with one associated constant a flag."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...ir import EnumDef, EnumKind
from .docs import doc_lines
from .naming import camel, upper


@dataclass(frozen=True)
class Member:
    name: str
    value: int
    doc: list[str]
    alias_of: str | None = None  # a value enum's later member with an earlier member's value


@dataclass(frozen=True)
class EnumView:
    name: str
    qualified: str
    bitmask: bool
    repr: str
    doc: list[str]
    members: list[Member] = field(default_factory=list)

    @property
    def mask(self) -> int:
        out = 0
        for m in self.members:
            out |= m.value
        return out


def repr_type(values: list[int]) -> str:
    """The smallest Rust integer holding every value."""
    low, high = min(values, default=0), max(values, default=0)
    for bits in (8, 16, 32, 64):
        if low >= 0 and high < 1 << bits:
            return f"u{bits}"
        if low >= -(1 << (bits - 1)) and high < 1 << (bits - 1):
            return f"i{bits}"
    raise ValueError(f"enum values {low}..{high} do not fit 64 bits")


def _member_word(e: EnumDef, entry: str) -> str:
    """The member's name without the group's prefix (``MAV_BATTERY_CHARGE_STATE_OK`` -> ``OK``)."""
    prefix = e.short_name + "_"
    return entry[len(prefix) :] if entry.startswith(prefix) and len(entry) > len(prefix) else entry


def enum_view(e: EnumDef) -> EnumView:
    bitmask = e.kind is not EnumKind.VALUE
    spell = upper if bitmask else camel
    members: list[Member] = []
    used: set[str] = set()
    first_of: dict[int, str] = {}
    for entry in e.entries:
        name = spell(_member_word(e, entry.name))
        if name in used or name in ("Self", "SELF"):
            name = spell(entry.name)
        used.add(name)
        value = 1 << entry.value if e.kind is EnumKind.BIT_INDEX else entry.value
        alias = None if bitmask else first_of.get(value)
        if alias is not None:  # Rust allows one variant a value: the later name is a constant
            name = upper(_member_word(e, entry.name))
        first_of.setdefault(value, name)
        members.append(Member(name, value, doc_lines(entry.doc), alias))
    return EnumView(
        name=camel(e.short_name),
        qualified=e.name,
        bitmask=bitmask,
        repr=repr_type([m.value for m in members]),
        doc=doc_lines(e.doc, notes=(f"Schema: `{e.name}` ({e.kind.value}).",)),
        members=members,
    )
