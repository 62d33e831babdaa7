"""A parameter's numbers: its Range, its Type (stated or inferred) and its Default.

apm.pdef.xml states no type and no default, so two optional fields of our own are read:
``Type`` (float, int8, int16, int32; AP_Float... spellings too) and ``Default``. Without ``Type``
a parameter is an integer when it has Values or a Bitmask, or an integral Increment (and Range),
in the smallest integer type holding every code and bound; else float32.
"""

from __future__ import annotations

import math
import re
from typing import NamedTuple

from ...errors import SchemaError
from ...ir import PrimitiveKind, PrimitiveType, Range
from .tree import Element

INT = re.compile(r"[+-]?[0-9]+")
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
TYPES: dict[str, PrimitiveType] = {
    "float": PrimitiveType(PrimitiveKind.FLOAT, 32),
    "int8": PrimitiveType(PrimitiveKind.INT, 8),
    "int16": PrimitiveType(PrimitiveKind.INT, 16),
    "int32": PrimitiveType(PrimitiveKind.INT, 32),
}
_TYPE_ALIASES = {"ap_float": "float", "ap_int8": "int8", "ap_int16": "int16", "ap_int32": "int32", "float32": "float"}


class Entry(NamedTuple):
    """One of a parameter's Values (code: label) or Bitmask bits (bit number: label)."""

    code: int
    label: str
    line: int


def parse_range(node: Element) -> Range:
    """``<field name="Range">min max</field>``."""
    parts = node.text.split()
    if len(parts) != 2 or not all(_NUMBER.fullmatch(p) for p in parts):
        raise node.error(f"expected Range as two numbers 'min max', got {node.text!r}")
    lo, hi = (_number(p) for p in parts)
    if lo > hi:
        raise node.error(f"expected Range min <= max, got {node.text!r}")
    return Range(minimum=lo, maximum=hi)


def parameter_type(
    fields: dict[str, Element],
    param: Element,
    name: str,
    rng: Range | None,
    values: list[Entry] | None,
    bits: list[Entry] | None,
) -> PrimitiveType:
    """The stated Type, or the inferred one; checked against the Range and the value codes."""
    if "Type" in fields:
        text = fields["Type"].text
        key = _TYPE_ALIASES.get(text.lower(), text.lower())
        if key not in TYPES:
            raise fields["Type"].error(f"expected Type float, int8, int16 or int32, got {text!r}")
        ptype = TYPES[key]
    else:
        ptype = _infer(fields, rng, values, bits)
    if ptype.kind is PrimitiveKind.INT and rng is not None:
        lo, hi = ptype.value_range or (0, 0)
        if not (isinstance(rng.minimum, int) and isinstance(rng.maximum, int)):
            raise fields["Range"].error(f"expected an integer Range for {ptype.name} parameter {name}")
        if rng.minimum < lo or rng.maximum > hi:
            raise fields["Range"].error(f"expected a Range within {ptype.name} ({lo}..{hi}) for {name}")
    if ptype.kind is PrimitiveKind.INT and values is not None:
        lo, hi = ptype.value_range or (0, 0)
        for code, _, where in values:
            if not lo <= code <= hi:
                raise SchemaError(
                    param.file, where, f"expected a value code within {ptype.name} for {name}, got {code}"
                )
    return ptype


def parse_default(node: Element, ptype: PrimitiveType, rng: Range | None, name: str) -> int | float:
    """``<field name="Default">``: a value of the parameter's type, within its Range."""
    text = node.text
    if ptype.kind is PrimitiveKind.INT:
        if not INT.fullmatch(text):
            raise node.error(f"expected an integer Default for {ptype.name} parameter {name}, got {text!r}")
        value: int | float = int(text)
        lo, hi = ptype.value_range or (0, 0)
        if not lo <= value <= hi:
            raise node.error(f"expected a Default within {ptype.name} ({lo}..{hi}), got {text!r}")
    else:
        if not _NUMBER.fullmatch(text):
            raise node.error(f"expected a number as Default of {name}, got {text!r}")
        value = float(text)
    if rng is not None and not _within(value, rng):
        raise node.error(f"expected a Default within Range {rng.minimum} {rng.maximum}, got {text!r}")
    return value


def _number(text: str) -> int | float:
    return int(text) if INT.fullmatch(text) else float(text)


def _within(value: float, rng: Range) -> bool:
    if rng.minimum is not None and value < rng.minimum:
        return False
    return not (rng.maximum is not None and value > rng.maximum)


def _infer(
    fields: dict[str, Element],
    rng: Range | None,
    values: list[Entry] | None,
    bits: list[Entry] | None,
) -> PrimitiveType:
    """apm.pdef.xml states no type: integers are recognised by values, bits or whole steps."""
    inc = fields.get("Increment")
    integral_step = inc is not None and INT.fullmatch(inc.text) is not None
    integral_range = rng is None or (isinstance(rng.minimum, int) and isinstance(rng.maximum, int))
    if bits is not None:
        top = max((code for code, _, _ in bits), default=0)
        return TYPES["int8" if top < 7 else "int16" if top < 15 else "int32"]
    if values is None and not (integral_step and integral_range):
        return TYPES["float"]
    codes = [code for code, _, _ in values or []]
    bounds = [] if rng is None else [float(b) for b in (rng.minimum, rng.maximum) if b is not None]
    span = [*codes, *bounds]
    for key in ("int8", "int16", "int32"):
        lo, hi = TYPES[key].value_range or (0, 0)
        if all(lo <= v <= hi and not math.isinf(v) for v in span):
            return TYPES[key]
    return TYPES["float"]
