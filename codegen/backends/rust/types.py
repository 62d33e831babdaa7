"""The Rust spelling of IR field types and of values in them (literals for defaults, constants and
test data). DSDL's odd widths widen to the next Rust integer; float16 is held in an f32."""

from __future__ import annotations

import math
import struct

from ...ir import ArrayType, FieldType, PrimitiveKind, PrimitiveType, StringType


def scalar(t: PrimitiveType) -> str:
    """The Rust type holding a value of ``t``."""
    if t.kind is PrimitiveKind.BOOL:
        return "bool"
    if t.kind is PrimitiveKind.CHAR:
        return "u8"
    if t.kind is PrimitiveKind.FLOAT:
        return "f64" if t.bits > 32 else "f32"
    width = next(w for w in (8, 16, 32, 64) if t.bits <= w)
    return ("u" if t.kind is PrimitiveKind.UINT else "i") + str(width)


def is_exact_width(t: PrimitiveType) -> bool:
    """True when the Rust type holds exactly the values of ``t`` (no width check needed)."""
    return (t.kind is not PrimitiveKind.UINT and t.kind is not PrimitiveKind.INT) or t.bits in (8, 16, 32, 64)


def element(t: FieldType) -> FieldType:
    """The innermost element type of an array (the type itself otherwise)."""
    while isinstance(t, ArrayType):
        t = t.element
    return t


def capacity(t: ArrayType | StringType) -> int:
    return t.capacity or 1


def f32_literal(value: float) -> str:
    """The shortest decimal that reads back as the same f32 (no excess precision for clippy)."""
    bits = struct.unpack("<f", struct.pack("<f", value))[0]
    for digits in range(1, 10):
        text = f"{bits:.{digits}g}"
        if struct.pack("<f", float(text)) == struct.pack("<f", value):
            return _decimal(text)
    raise AssertionError(value)  # nine significant digits always round-trip an f32


def _decimal(text: str) -> str:
    """A Python float spelling as a Rust float literal (``1e-05`` -> ``1e-05``, ``3`` -> ``3.0``)."""
    if "e" in text or "." in text or "inf" in text or "nan" in text:
        mantissa, _, exponent = text.partition("e")
        if "." not in mantissa:
            mantissa += ".0"
        return mantissa + ("e" + exponent if exponent else "")
    return text + ".0"


def float_literal(value: float, rust: str) -> str:
    """A float of type ``rust`` (f32 / f64), NaN and the infinities as the type's constants."""
    if math.isnan(value):
        return f"{rust}::NAN"
    if math.isinf(value):
        return f"{rust}::INFINITY" if value > 0 else f"{rust}::NEG_INFINITY"
    return f32_literal(value) if rust == "f32" else _decimal(repr(float(value)))


def scalar_literal(t: PrimitiveType, value: int | float | bool | str) -> str:
    """A value of ``t`` as a Rust expression."""
    rust = scalar(t)
    if rust == "bool":
        return "true" if value else "false"
    if isinstance(value, str):  # a char: its byte
        return str(value.encode("latin-1")[0]) if value else "0"
    if rust in ("f32", "f64"):
        return float_literal(float(value), rust)
    return str(int(value))


def f64_bound(value: float) -> str:
    """A bound compared in f64 (the Python validators compare the exact value as a double)."""
    return float_literal(float(value), "f64")


def equals(t: PrimitiveType, value: int | float, expr: str, negate: bool = False) -> str:
    """``expr`` (of type ``t``) is ``value`` (NaN by ``is_nan``: it equals nothing), or is not."""
    if isinstance(value, float) and math.isnan(value):
        return ("!" if negate else "") + f"{expr}.is_nan()"
    return f"{expr} {'!=' if negate else '=='} {scalar_literal(t, value)}"
