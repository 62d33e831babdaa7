"""The wire layout of a DroneCAN type as a comment above its codec: one line per field giving its bit
offset, its width and the DSDL line it comes from, so a reviewer checks the codec field by field against
the definition without working the offsets out by hand."""

from __future__ import annotations

import textwrap

from .....ir import ArrayType, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType
from ...field_source import type_text
from ...formatting import LINE_LENGTH
from ...literals import comment
from .plan import Planner


def _sized(planner: Planner, t: FieldType) -> bool:
    """Whether every value of ``t`` takes the same number of bits (no dynamic array, no union inside)."""
    if isinstance(t, PrimitiveType):
        return True
    if isinstance(t, ArrayType):
        return not t.dynamic and _sized(planner, t.element)
    if isinstance(t, CompositeType):
        m = planner.message(t)
        return m.dronecan is not None and not m.dronecan.union and all(_sized(planner, f.type) for f in m.fields)
    return False


def _varying(planner: Planner, t: FieldType, tail: bool) -> str:
    """How a field of varying size is made up, in bits."""
    if isinstance(t, ArrayType) and t.dynamic:
        element = f"{planner.fixed_bits(t.element)} bits" if _sized(planner, t.element) else "elements"
        count = f"<={t.capacity} x {element}"
        if tail and planner.tao_eligible(t):
            return f": {count}, the tail array (no length prefix with TAO)"
        return f": a {(t.capacity or 0).bit_length()}-bit length, then {count}"
    return ": varying size"


def _what(f: Field) -> str:
    if f.is_padding and isinstance(f.type, PrimitiveType) and f.type.kind is PrimitiveKind.VOID:
        return f"void{f.type.bits} (padding)"
    return f"{type_text(f.type)} {f.name}"


def field_map(planner: Planner, msg: Message) -> list[str]:
    """Comment lines (unindented) mapping each field of ``msg`` to its bits; a union's branches all start
    after the tag. Offsets past a field of varying size count from its end (``name+8``)."""
    info = msg.dronecan
    union = info is not None and info.union
    source = msg.location.file.rsplit("/", 1)[-1]
    out = comment(f"Wire layout ({source}), bits from the start of the payload:", "")
    offset = 0
    after = ""  # the last field of varying size so far: offsets count from its end
    if union:
        tag = max(len(msg.fields) - 1, 1).bit_length()
        out.append(f"#   bits {'0-' + str(tag - 1):<9} union tag: the index of the branch held")
        offset = tag
    last = len(msg.fields) - 1
    for i, f in enumerate(msg.fields):
        at = f"{after}+{offset}" if after else str(offset)
        if _sized(planner, f.type):
            bits, more = f"{at}-{offset + planner.fixed_bits(f.type) - 1}" if not after else at, ""
        else:
            bits, more = f"{at}-", _varying(planner, f.type, tail=i == last)
        row = f"bits {bits:<9} {_what(f)}{more}  (line {f.location.line})"
        # wrapped where the class body's indent leaves too little room (continuation lines indented);
        # the text is DSDL names and numbers, which the DSDL frontend keeps to identifiers
        wrapped = textwrap.wrap(row, LINE_LENGTH - 4 - 8, break_long_words=False, break_on_hyphens=False)
        out += ["#   " + wrapped[0], *("#       " + line for line in wrapped[1:])]
        if union:
            continue
        if _sized(planner, f.type):
            offset += planner.fixed_bits(f.type)
        else:
            offset, after = 0, f.name
    return out
