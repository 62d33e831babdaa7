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


# names a type must not take in a message module: the prelude's and what the module imports
TAKEN = frozenset(
    "Option Some None Result Ok Err Default Clone Copy Debug PartialEq Eq PartialOrd Ord Hash Send Sync Sized "
    "Drop Fn FnMut FnOnce Iterator IntoIterator Extend From Into TryFrom TryInto AsRef AsMut ToOwned ToString "
    "String Vec Box Self Problems Problem Rule Validate Same BitReader BitWriter".split()
)


def enum_view(e: EnumDef, taken: frozenset[str] = TAKEN) -> EnumView:
    """The Rust type of ``e``; a name in ``taken`` (the prelude's, the message struct's) gets the
    suffix ``Kind`` (a value enum) or ``Flags`` (a bitmask)."""
    bitmask = e.kind is not EnumKind.VALUE
    spell = upper if bitmask else camel
    members: list[Member] = []
    used: set[str] = set()
    first_of: dict[int, str] = {}
    for entry in e.entries:
        # names that differ only in separators ("CR_7_5_M", "CR_75_M") spell the same: the later
        # member takes its full name, then its value besides
        candidates = (spell(_member_word(e, entry.name)), spell(entry.name), f"{spell(entry.name)}{entry.value}")
        name = next((c for c in candidates if c not in used and c not in ("Self", "SELF")), None)
        if name is None:
            raise ValueError(f"{e.name}: no free Rust name for {entry.name}")
        used.add(name)
        value = 1 << entry.value if e.kind is EnumKind.BIT_INDEX else entry.value
        alias = None if bitmask else first_of.get(value)
        if alias is not None:  # Rust allows one variant a value: the later name is a constant
            name = upper(_member_word(e, entry.name))
            name = name if name not in used else upper(entry.name)
            used.add(name)
        first_of.setdefault(value, name)
        members.append(Member(name, value, doc_lines(entry.doc), alias))
    name = camel(e.short_name)
    if name in taken:
        name += "Flags" if bitmask else "Kind"
    return EnumView(
        name=name,
        qualified=e.name,
        bitmask=bitmask,
        repr=repr_type([m.value for m in members]),
        doc=doc_lines(e.doc, notes=(f"Schema: `{e.name}` ({e.kind.value}).",)),
        members=members,
    )
