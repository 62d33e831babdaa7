"""Literal forms that MAVLink XML attributes may hold, parsed without eval().

pymavlink evaluates enum entry values with eval(); we only let through the forms the MAVLink
XSD allows (plus an optional minus sign) and compute their values here ourselves.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping

from ...ir import PrimitiveKind, PrimitiveType, Sentinel

# Every form reaching pymavlink's eval() must match this; each is also a valid Python literal
# (no leading zeros in decimals: eval("007") is a SyntaxError).
_ENTRY_VALUE = re.compile(
    r"-?(?:(?P<dec>0|[1-9][0-9]{0,19})|0[xX](?P<hex>[0-9a-fA-F]{1,16})|0[bB](?P<bin>[01]{1,64})"
    r"|2\*\*(?P<pow>[0-9]{1,2}))"
)
ENTRY_VALUE_FORMS = "an integer literal: decimal, 0x hex, 0b binary or 2**N, optionally with a leading '-'"

_INTEGER = re.compile(r"-?(?:0|[1-9][0-9]*)|-?0[xX][0-9a-fA-F]+")
_FLOAT = re.compile(r"-?(?:[0-9]+\.[0-9]*|\.[0-9]+|[0-9]+)(?:[eE][-+]?[0-9]+)?")
_LIMIT = re.compile(r"(U?)INT(8|16|32|64)_(MAX|MIN)")
_NAN = frozenset({"NaN", "NAN", "nan"})
_MAX_POSITIONS = 255  # no array in a 255-byte payload has more elements

SENTINEL_FORMS = (
    "a number, NaN, INTn_MAX/INTn_MIN/UINTn_MAX/UINTn_MIN, an entry of the field's enum, "
    "or for an array one of those in brackets ([X] per element, [X:] when the first element is X, "
    "[X1,,X3,] per position)"
)


def entry_value(text: str) -> int | None:
    """The value of an enum entry ``value`` attribute, or None when it is not an allowed form."""
    m = _ENTRY_VALUE.fullmatch(text)
    if m is None:
        return None
    sign = -1 if text.startswith("-") else 1
    if m["dec"] is not None:
        return sign * int(m["dec"], 10)
    if m["hex"] is not None:
        return sign * int(m["hex"], 16)
    if m["bin"] is not None:
        return sign * int(m["bin"], 2)
    power = int(m["pow"], 10)
    return sign * (1 << power) if power <= 64 else None


def number(text: str) -> int | float | None:
    """An integer (decimal or hex) or float literal, NaN included; None for anything else."""
    if _INTEGER.fullmatch(text):
        negative = text.startswith("-")
        digits = text[1:] if negative else text
        value = int(digits, 16) if digits[:2] in ("0x", "0X") else int(digits, 10)
        return -value if negative else value
    if _FLOAT.fullmatch(text):
        return float(text)
    if text in _NAN:
        return math.nan
    return None


def _limit(text: str) -> int | None:
    m = _LIMIT.fullmatch(text)
    if m is None:
        return None
    bits = int(m[2])
    if m[1]:  # unsigned
        return (1 << bits) - 1 if m[3] == "MAX" else 0
    return (1 << (bits - 1)) - 1 if m[3] == "MAX" else -(1 << (bits - 1))


def _scalar(text: str, enum_values: Mapping[str, int]) -> int | float | None:
    value: int | float | None = number(text)
    if value is None:
        value = _limit(text)
    if value is None:
        value = enum_values.get(text)
    return value


def sentinel(text: str, enum_values: Mapping[str, int]) -> Sentinel | None:
    """The Sentinel an ``invalid`` attribute spells, or None when the form is not understood.

    The forms are those of the MAVLink guide's field ``invalid`` attribute (mavlink-devguide,
    en/guide/xml_schema.md): ``X``; ``[X]``: every array element that holds X is invalid;
    ``[X:]``: all elements are invalid when the *first* holds X (``first_decides``; an X elsewhere
    marks nothing); ``[X1,,X3,]`` marks elements by position (``[0,]``: only the first), an empty
    position having no marker.
    """
    if not (text.startswith("[") and text.endswith("]")):
        value = _scalar(text, enum_values)
        return None if value is None else Sentinel(value=value, text=text)
    inner = text[1:-1]
    if "," in inner:
        items = inner.split(",")
        if items[-1] == "":
            items.pop()  # the list's closing comma
        if len(items) > _MAX_POSITIONS:
            return None
        markers = tuple(None if item == "" else _scalar(item, enum_values) for item in items)
        given = [m for m in markers if m is not None]
        if len(given) != sum(1 for item in items if item != "") or not given:
            return None  # an item not understood, or no marker at all
        return Sentinel(value=given[0], text=text, per_element=True, elements=markers)
    first = inner.endswith(":")
    value = _scalar(inner[:-1] if first else inner, enum_values)
    if value is None:
        return None
    return Sentinel(value=value, text=text, per_element=not first, first_decides=first)


def fits(value: int | float, element: PrimitiveType) -> bool:
    """Whether a sentinel value can be stored in a field of this element type."""
    if isinstance(value, float) and math.isnan(value):
        return element.kind is PrimitiveKind.FLOAT
    if element.kind is PrimitiveKind.CHAR:
        return isinstance(value, int) and 0 <= value <= 255
    bounds = element.value_range
    if bounds is None:
        return False
    if element.kind is not PrimitiveKind.FLOAT and isinstance(value, float) and not value.is_integer():
        return False  # a fraction, or an infinity (1e999), in an integer field
    return bounds[0] <= value <= bounds[1]
