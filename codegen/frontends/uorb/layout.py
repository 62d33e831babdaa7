"""The C struct PX4 generates for a uORB message, which is also the ULog record layout.

PX4's generator (msg/tools/px_generate_uorb_topic_helper.py) stable-sorts the fields by the
size of one element, largest first, with nested message types (size 0 for sorting) last, so
every builtin lands naturally aligned without padding. It then walks the sorted fields:
before each nested struct it inserts ``uint8 _paddingN[k]`` to reach a multiple of 8, and at
the end pads the whole struct to a multiple of 8 (the 64-bit ``timestamp`` alignment). A
nested struct counts with its own padded size. ``timestamp`` gets no special place: it is an
ordinary uint64 and comes first only because it is the first 8-byte field of the file.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ...ir import StructSlot

ALIGN = 8


@dataclass(frozen=True)
class Member:
    """One field as the layout sees it."""

    name: str
    element_size: int  # bytes of one builtin element; 0 for a nested struct
    count: int = 1  # array length, 1 for scalars
    nested_size: int = 0  # padded size of the nested struct (element_size 0)

    @property
    def size(self) -> int:
        return (self.element_size or self.nested_size) * self.count


def sort_members(members: Sequence[Member]) -> list[Member]:
    """PX4's field order: by element size, largest first, stable; nested structs last."""
    return sorted(members, key=lambda m: m.element_size, reverse=True)


def px4_layout(members: Sequence[Member]) -> tuple[int, tuple[StructSlot, ...]]:
    """(struct size, slots) with PX4's padding slots named ``_padding0``, ``_padding1``..."""
    slots: list[StructSlot] = []
    offset = 0

    def pad() -> None:
        nonlocal offset
        gap = -offset % ALIGN
        if gap:
            slots.append(StructSlot(f"_padding{sum(s.field is None for s in slots)}", offset, gap, None))
            offset += gap

    for m in sort_members(members):
        if m.element_size == 0:
            pad()
        slots.append(StructSlot(m.name, offset, m.size, m.name))
        offset += m.size
    pad()
    return offset, tuple(slots)
