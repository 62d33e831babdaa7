"""What a Rust converter needs of the messages it reads and writes, apart from the rules (the C
backend's ``convert_values``, in Rust): literals for the values rules name, a message's defaults
(what a fresh Python object holds: sentinels, constants, zero), and whether a field differs from
its default (NaN equal to NaN, arrays by their elements, text up to its first NUL), so the loss
report names the same source fields nobody read."""

from __future__ import annotations

import math
import struct

from ...ir import ArrayType, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema, StringType
from .model import type_path
from .naming import field_ident
from .types import capacity, float_literal, scalar


class Unsupported(Exception):
    """A rule (or value) the Rust converters do not write yet: its mapping is left out of the crate."""


def f32(x: float) -> float:
    """``x`` rounded to the nearest float32 (an infinity beyond it)."""
    try:
        value: float = struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
    return value


def f32_literal(value: float) -> str:
    """The f32 nearest ``value``, typed (``1.5f32``; NaN and the infinities as constants)."""
    v = f32(value) if math.isfinite(value) else value
    text = float_literal(v, "f32")
    return text if "::" in text else text + "_f32"


def f64_literal(value: float) -> str:
    text = float_literal(float(value), "f64")
    return text if "::" in text else text + "_f64"


def int_literal(value: int, rust: str) -> str:
    return f"{value}_{rust}"


def literal(t: PrimitiveType, value: object) -> str:
    """``value`` as a Rust expression of the type holding ``t``."""
    if t.kind is PrimitiveKind.BOOL:
        return "true" if value else "false"
    if isinstance(value, str | bytes) or value is None:
        raise Unsupported(f"the value {value!r}")
    assert isinstance(value, int | float)
    if t.kind is PrimitiveKind.FLOAT:
        return f64_literal(float(value)) if t.bits > 32 else f32_literal(float(value))
    rust = scalar(t)
    if t.kind is PrimitiveKind.CHAR:
        return f"{int(value) & 0xFF}_u8"
    return int_literal(int(value), rust)


def primitive(f: Field) -> PrimitiveType | None:
    t = f.type
    while isinstance(t, ArrayType):
        t = t.element
    return t if isinstance(t, PrimitiveType) else None


def rust_type(qualified: str) -> str:
    return type_path(qualified)


def defaults(schema: Schema, msg: Message, target: str, depth: int = 0) -> list[str]:
    """Statements giving ``target`` (a struct place made by ``new()``) what a fresh Python object
    of ``msg`` holds: sentinels, per-position markers, constants and defaults; zero elsewhere (as
    the C library's converters start from a zeroed struct)."""
    out: list[str] = []
    for f in msg.fields:
        if f.is_padding:
            continue
        t = f.type
        name = f"{target}.{field_ident(f.name)}"
        s = f.invalid
        if isinstance(t, CompositeType):
            if depth >= 8:
                raise Unsupported("nesting too deep")
            out += defaults(schema, schema.message(t.name), name, depth + 1)
        elif isinstance(t, PrimitiveType):
            value = s.value if s is not None and not s.per_element else f.const if f.const is not None else f.default
            if f.pattern is not None or value is None:
                value = 0
            out.append(f"{name} = {literal(t, value)};")
        elif isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
            cap = capacity(t)
            if t.dynamic or not t.capacity or s is None:
                items = [literal(t.element, 0)] * cap
            else:
                items = [literal(t.element, (s.marker_at(i) or 0) if s.elements else s.value) for i in range(cap)]
            if len(set(items)) == 1:
                out.append(f"{name} = [{items[0]}; {cap}];")
            else:
                out.append(f"{name} = [{', '.join(items)}];")
            if t.dynamic:
                out.append(f"{name}_len = 0;")
        elif isinstance(t, StringType):
            if f.const or f.default:
                raise Unsupported(f"{msg.qualified_name}.{f.name}: a text default")
            out.append(f"{name} = [0; {capacity(t)}];")
        elif isinstance(t, ArrayType):
            raise Unsupported(f"{msg.qualified_name}.{f.name}: an array of messages")
    return out


def _char_text(t: FieldType) -> bool:
    if isinstance(t, StringType):
        return True
    return isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.element.kind is PrimitiveKind.CHAR


def differs(t: FieldType, a: str, b: str) -> str:
    """A Rust condition: value ``a`` differs from ``b`` (Python's ``differs``)."""
    if isinstance(t, PrimitiveType | CompositeType):
        return f"!{a}.same(&{b})"
    if _char_text(t):
        return f"!same_chars(&{a}, &{b})"
    if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
        if t.dynamic:
            cap = capacity(t)
            return f"{a}_len != {b}_len || !{a}[..{a}_len.min({cap})].same(&{b}[..{a}_len.min({cap})])"
        return f"!{a}.same(&{b})"
    raise Unsupported(f"comparing a {type(t).__name__}")
