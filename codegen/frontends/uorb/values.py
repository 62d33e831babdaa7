"""Literal values as uORB .msg files spell them: constant values, @range bounds, @invalid values."""

from __future__ import annotations

import math
import re

from ...ir import PrimitiveKind, PrimitiveType

_INT = re.compile(r"[+-]?(?:0[xX][0-9a-fA-F]+|0[bB][01]+|[0-9]+)\Z")
_FLOAT = re.compile(r"[+-]?(?:[0-9]+\.[0-9]*|\.[0-9]+|[0-9]+)(?:[eE][+-]?[0-9]+)?\Z")
_SPECIAL_FLOATS = {"nan": math.nan, "inf": math.inf, "infinity": math.inf}
_FLT_MAX = 3.4028234663852886e38

# C limit macros some schemas use instead of a number (``[@invalid INT16_MAX]``)
NAMED_LIMITS: dict[str, int | float] = {"FLT_MAX": _FLT_MAX, "DBL_MAX": 1.7976931348623157e308}
for _bits in (8, 16, 32, 64):
    NAMED_LIMITS[f"INT{_bits}_MAX"] = (1 << (_bits - 1)) - 1
    NAMED_LIMITS[f"INT{_bits}_MIN"] = -(1 << (_bits - 1))
    NAMED_LIMITS[f"UINT{_bits}_MAX"] = (1 << _bits) - 1


def parse_int(text: str) -> int | None:
    """A decimal, hex (0x) or binary (0b) integer with optional sign; None if not one.

    Leading zeros stay decimal, as PX4's generator reads constants with Python's ``int``.
    """
    if not _INT.match(text):
        return None
    sign = -1 if text.startswith("-") else 1
    digits = text.lstrip("+-")
    if digits[:2].lower() == "0x":
        return sign * int(digits[2:], 16)
    if digits[:2].lower() == "0b":
        return sign * int(digits[2:], 2)
    return sign * int(digits, 10)


def parse_number(text: str) -> int | float | None:
    """An integer (kept exact), a float literal, NaN/inf, or a C limit name; None otherwise."""
    as_int = parse_int(text)
    if as_int is not None:
        return as_int
    if _FLOAT.match(text):
        return float(text)
    sign = -1.0 if text.startswith("-") else 1.0
    bare = text.lstrip("+-")
    if bare.lower() in _SPECIAL_FLOATS:
        return sign * _SPECIAL_FLOATS[bare.lower()]
    if bare in NAMED_LIMITS:
        return -NAMED_LIMITS[bare] if text.startswith("-") else NAMED_LIMITS[bare]
    return None


def fits(ptype: PrimitiveType, value: int | float) -> bool:
    """Whether ``value`` is representable in ``ptype`` (NaN and infinities only in floats)."""
    if ptype.kind is PrimitiveKind.FLOAT:
        if math.isnan(value) or math.isinf(value):
            return True
        return ptype.bits == 64 or abs(value) <= _FLT_MAX
    if isinstance(value, float):
        if not value.is_integer():
            return False
        value = int(value)
    if ptype.kind is PrimitiveKind.CHAR:
        return 0 <= value <= 255
    bounds = ptype.value_range
    return bounds is not None and bounds[0] <= value <= bounds[1]


def describe_range(ptype: PrimitiveType) -> str:
    """The representable range of an integer type, for error messages (``0..255``)."""
    if ptype.kind is PrimitiveKind.CHAR:
        return "0..255"
    bounds = ptype.value_range
    if bounds is None or ptype.kind is PrimitiveKind.FLOAT:
        return f"a finite {ptype.name} value"
    return f"{int(bounds[0])}..{int(bounds[1])}"
