"""One comment line above each field's check in ``validate()``, saying in words what the fast test below it
checks (the type's range, the schema's bounds, the "unknown" sentinel, the enum it must belong to) and the
schema line it comes from, so a reviewer reads the rule instead of working it out from masks."""

from __future__ import annotations

from ....ir import EnumKind, Field, Message, Schema
from ..field_source import type_text
from ..literals import comment


def _number(value: int | float) -> str:
    return repr(value) if isinstance(value, float) else str(value)


def _enum_text(schema: Schema, name: str) -> str:
    short = name.rsplit(".", 1)[-1]
    try:
        kind = schema.enum(name).kind
    except KeyError:
        return f"a value of {short}"
    return f"bits of {short} only" if kind is not EnumKind.VALUE else f"a value of {short}"


def check_comment(schema: Schema, msg: Message, f: Field) -> list[str]:
    """``# name (file:line): fits <type>; <bounds>; <enum>; <sentinel> means unknown``, wrapped to the line."""
    parts = [f"fits {type_text(f.type)}"]
    r = f.range
    if r is not None and (r.minimum is not None or r.maximum is not None):
        low = "" if r.minimum is None else _number(r.minimum) + (" <" if r.exclusive_minimum else " <=")
        high = "" if r.maximum is None else ("< " if r.exclusive_maximum else "<= ") + _number(r.maximum)
        parts.append(f"{low} value {high}".strip())
    if f.enums:
        parts.append(" or ".join(_enum_text(schema, name) for name in f.enums))
    if f.choices:
        parts.append("one of " + ", ".join(str(c) for c in f.choices))
    if f.invalid is not None:
        parts.append(f"{f.invalid.text} means unknown (accepted)")
    where = f"{msg.location.file.rsplit('/', 1)[-1]}:{f.location.line}"
    pad = " " * 12  # where the check stands: in the try of validate(), in the class
    return [line[len(pad) :] for line in comment(f"{f.name} ({where}): " + "; ".join(parts), pad)]
