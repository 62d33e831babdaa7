"""What a C converter needs of the messages it reads and writes, apart from the rules: C literals
for the values rules name, a message's defaults (what a fresh Python object holds: sentinels,
constants, zero), and whether a field differs from its default (NaN equal to NaN, arrays by
their elements), so the loss report names the same source fields nobody read."""

from __future__ import annotations

import math
import struct

from ...ir import ArrayType, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema, StringType
from .types import ident, scalar, type_name


class Unsupported(Exception):
    """A rule (or value) the C converters do not write yet: its mapping is left out of the library."""


def f32(x: float) -> float:
    """``x`` rounded to the nearest float32 (an infinity beyond it)."""
    try:
        value: float = struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
    return value


def f32_literal(value: float) -> str:
    """A C float expression of the float32 nearest ``value`` (NaN and the infinities by their bits)."""
    v = f32(value) if math.isfinite(value) else value
    if math.isnan(v):
        return "battgen_f32_from(0x7FC00000u)"  # NAN, without <math.h> (a freestanding build has none)
    if math.isinf(v):
        return "battgen_f32_from(0x7F800000u)" if v > 0 else "battgen_f32_from(0xFF800000u)"
    return repr(v) + "f" if ("." in repr(v) or "e" in repr(v)) else repr(v) + ".0f"


def f64_literal(value: float) -> str:
    if math.isnan(value):
        return "battgen_f64_from(0x7FF8000000000000ULL)"
    if math.isinf(value):
        return "battgen_f64_from(0x7FF0000000000000ULL)" if value > 0 else "battgen_f64_from(0xFFF0000000000000ULL)"
    text = repr(float(value))
    return text if ("." in text or "e" in text) else text + ".0"


def int_literal(value: int, c: str) -> str:
    if c in ("uint64_t", "int64_t"):
        if value == -(2**63):
            return "(-9223372036854775807LL - 1)"
        return f"{value}{'ULL' if c == 'uint64_t' else 'LL'}"
    if c.startswith("u"):
        return f"{value}u"
    return f"({value})" if value < 0 else str(value)


def literal(t: PrimitiveType, value: object) -> str:
    """``value`` as a C expression of the C type holding ``t``."""
    if t.kind is PrimitiveKind.BOOL:
        return "true" if value else "false"
    if isinstance(value, str | bytes) or value is None:
        raise Unsupported(f"the value {value!r}")
    assert isinstance(value, int | float)
    if t.kind is PrimitiveKind.FLOAT:
        return f64_literal(float(value)) if t.bits > 32 else f32_literal(float(value))
    if t.kind is PrimitiveKind.CHAR:
        return f"(char){int(value)}"
    c = scalar(t)
    return f"({c}){int_literal(int(value), c)}"


def primitive(f: Field) -> PrimitiveType | None:
    t = f.type
    while isinstance(t, ArrayType):
        t = t.element
    return t if isinstance(t, PrimitiveType) else None


def defaults(schema: Schema, msg: Message, target: str, depth: int = 0) -> list[str]:
    """Statements giving ``target`` (a struct lvalue, zeroed before) what a fresh Python object of
    ``msg`` holds: sentinels, per-position markers, constants and defaults; zero elsewhere."""
    out: list[str] = []
    for f in msg.fields:
        if f.is_padding or f.pattern is not None:
            continue
        t = f.type
        name = f"{target}.{ident(f.name)}"
        s = f.invalid
        if isinstance(t, CompositeType) and depth < 8:
            out += defaults(schema, schema.message(t.name), name, depth + 1)
        elif isinstance(t, PrimitiveType):
            value = s.value if s is not None and not s.per_element else f.const if f.const is not None else f.default
            if (value is not None and value != 0) or (isinstance(value, float) and math.copysign(1.0, value) < 0):
                out.append(f"{name} = {literal(t, value)};")
        elif isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and s is not None:
            if t.dynamic or not t.capacity:
                continue
            for i in range(t.capacity):
                v = (s.marker_at(i) or 0) if s.elements else s.value
                if v != 0:
                    out.append(f"{name}[{i}] = {literal(t.element, v)};")
        elif isinstance(t, StringType) and (f.const or f.default):
            raise Unsupported(f"{msg.qualified_name}.{f.name}: a text default")
    return out


def _differs_primitive(t: PrimitiveType, a: str, b: str) -> str:
    if t.kind is PrimitiveKind.FLOAT:
        return f"!battgen_f{64 if t.bits > 32 else 32}_same({a}, {b})"
    return f"{a} != {b}"


def differs(schema: Schema, t: FieldType, a: str, b: str, depth: int = 0) -> list[str]:
    """Statements setting ``d = true`` when value ``a`` differs from ``b`` (Python's ``differs``)."""
    if isinstance(t, PrimitiveType):
        return [f"if ({_differs_primitive(t, a, b)}) {{ d = true; }}"]
    if isinstance(t, CompositeType) and depth < 8:
        m = schema.message(t.name)
        out: list[str] = []
        for f in m.fields:
            if not f.is_padding:
                out += differs(schema, f.type, f"{a}.{ident(f.name)}", f"{b}.{ident(f.name)}", depth + 1)
        return out
    if isinstance(t, StringType):
        # text as Python holds it: up to the first NUL
        return [f"if (!battgen_same_chars({a}, {b}, {(t.capacity or 0) + 1}u)) {{ d = true; }}"]
    if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
        el = t.element
        if t.dynamic:
            return [
                f"if ({a}_len != {b}_len) {{ d = true; }}",
                f"for (i = 0; i < {a}_len && i < {t.capacity or 1}u; i++) {{",
                f"if ({_differs_primitive(el, f'{a}[i]', f'{b}[i]')}) {{ d = true; }}",
                "}",
            ]
        if el.kind is PrimitiveKind.CHAR:  # a char array is text
            return [f"if (!battgen_same_chars({a}, {b}, {t.capacity or 1}u)) {{ d = true; }}"]
        return [
            f"for (i = 0; i < {t.capacity or 1}u; i++) {{",
            f"if ({_differs_primitive(el, f'{a}[i]', f'{b}[i]')}) {{ d = true; }}",
            "}",
        ]
    raise Unsupported(f"comparing a {type(t).__name__}")


def c_type(qualified: str) -> str:
    return type_name(qualified)
