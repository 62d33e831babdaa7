"""How NaN and the infinities are spelled where JSON has no number for them.

JSON has no NaN or infinity, so every JSON battgen writes (the IR's JSON form, JSON Schema
constants, validate reports, converted records) spells them as the strings ``"NaN"``,
``"Infinity"`` and ``"-Infinity"``. Readers also take Python's spellings ``"nan"``, ``"inf"``
and ``"-inf"`` (what the generated ``from_dict`` accepts, and the JSON Schema allows).
"""

from __future__ import annotations

import math

NAN = "NaN"
INFINITY = "Infinity"
NEG_INFINITY = "-Infinity"

# every accepted spelling of each value, the written one first
NAN_SPELLINGS = (NAN, "nan")
INFINITY_SPELLINGS = (INFINITY, "inf")
NEG_INFINITY_SPELLINGS = (NEG_INFINITY, "-inf")
_READ: dict[str, float] = dict.fromkeys(NAN_SPELLINGS, math.nan)
_READ |= dict.fromkeys(INFINITY_SPELLINGS, math.inf)
_READ |= dict.fromkeys(NEG_INFINITY_SPELLINGS, -math.inf)


def to_json_number(value: float) -> float | str:
    """``value`` as JSON data: itself when finite, else its string spelling."""
    if math.isnan(value):
        return NAN
    if math.isinf(value):
        return INFINITY if value > 0 else NEG_INFINITY
    return value


def from_json_number(value: object) -> float | None:
    """The number a JSON value stands for: a number (not a bool) as a float, a spelling of NaN or
    an infinity as that float; None for anything else."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str):
        return _READ.get(value)
    return None


def to_json_data(value: object) -> object:
    """``value`` as strict JSON data (what ``json.dumps(..., allow_nan=False)`` takes): non-finite
    floats spelled, bytes as lists of byte values, tuples and sets as lists (sets sorted), mapping
    keys as strings, and any other object as its ``str``."""
    # the common cases first: this runs once per value of every converted record
    if isinstance(value, float):
        return value if math.isfinite(value) else to_json_number(value)
    if value is None or isinstance(value, bool | str) or type(value) is int:
        return value
    if isinstance(value, list | tuple):
        return [to_json_data(v) for v in value]
    if isinstance(value, dict):
        return {str(k): to_json_data(v) for k, v in value.items()}
    return _other_json_data(value)


def _other_json_data(value: object) -> object:
    if isinstance(value, int):
        return int(value)  # an IntEnum member as its plain value
    if isinstance(value, bytes | bytearray):
        return list(value)
    if isinstance(value, set | frozenset):
        return sorted((to_json_data(v) for v in value), key=repr)
    return str(value)
