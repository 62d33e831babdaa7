"""Dimensions, IR type and value constraints of a typed dt-schema property.

Dimensions follow dt-schema's rules: an ``items`` list fixes the length to its size unless
minItems/maxItems say otherwise; without ``items``, a lone minItems or maxItems fixes the length;
a unit-suffix property written as a plain number (const/enum/minimum/maximum) is one value; a
unit-suffix matrix written as one flat list is a single row.  A length of (n, n) is a fixed
array (``dynamic=False``); an open upper bound is ``capacity=None``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from ..ir import ArrayType, FieldType, PrimitiveKind, PrimitiveType, Range, StringType
from .devicetree_data import TypeDef
from .devicetree_yaml import YMap

Dim = tuple[int, int | None]  # (min items, max items or None when unbounded)

_INT_KEYS = ("const", "enum", "minimum", "maximum")
_RANGE_KEYS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
UNKNOWN_TYPE = ArrayType(PrimitiveType(PrimitiveKind.UINT, 8), None, dynamic=True)  # raw property bytes


def _int(value: Any) -> int | None:
    return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else None


def is_int_schema(schema: Any) -> bool:
    if not isinstance(schema, YMap):
        return False
    for key in _INT_KEYS:
        value = schema.get(key)
        first = value[0] if isinstance(value, list) and value else value
        if isinstance(first, int) and not isinstance(first, bool):
            return True
    return False


def _is_matrix_schema(schema: YMap) -> bool:
    items = schema.get("items")
    rows = items if isinstance(items, list) else [items]
    return any(isinstance(r, YMap) and r.keys() & {"items", "minItems", "maxItems"} for r in rows)


def dim_of(schema: Any, default_min: int) -> Dim:
    if not isinstance(schema, YMap):
        return (default_min, None)
    items, lo, hi = schema.get("items"), _int(schema.get("minItems")), _int(schema.get("maxItems"))
    if isinstance(items, list):
        return (lo if lo is not None else len(items), hi if hi is not None else len(items))
    if items is not None:
        return (lo if lo is not None else default_min, hi)
    if lo is None and hi is None:
        return (default_min, None)
    return (lo if lo is not None else hi or 0, hi if hi is not None else lo)


@dataclass(frozen=True)
class Shape:
    outer: Dim | None  # None for scalars
    inner: Dim | None  # rows of a matrix
    row_schema: Any  # the schema of one row (matrix) or of the element list (array)


def shape_of(td: TypeDef, schema: Any, from_suffix: bool) -> Shape:
    default = td.min_items or 0
    if td.shape == "scalar":
        return Shape(None, None, None)
    plain_number = (
        from_suffix
        and is_int_schema(schema)
        and not (isinstance(schema, YMap) and schema.keys() & {"items", "minItems", "maxItems"})
    )
    if td.shape == "array":
        return Shape((1, 1) if plain_number else dim_of(schema, default), None, schema)
    inner_default: Dim = (1, td.inner_max_items)
    if plain_number:
        return Shape((1, 1), (1, 1), schema)
    if not isinstance(schema, YMap):
        return Shape((default, None), inner_default, None)
    if _is_matrix_schema(schema):
        items = schema["items"]
        row = items[0] if isinstance(items, list) else items
        inner = dim_of(row, 1) if not isinstance(items, list) or len(items) == 1 else (0, None)
        if inner[1] is None and td.inner_max_items is not None:
            inner = (inner[0], td.inner_max_items)
        return Shape(dim_of(schema, default), inner, row)
    if from_suffix and schema.keys() & {"items", "minItems", "maxItems"}:
        return Shape((1, 1), dim_of(schema, 1), schema)  # one row, written flat
    return Shape(dim_of(schema, default), inner_default, None)


def element_type(td: TypeDef) -> FieldType:
    if td.value == "flag":
        return PrimitiveType(PrimitiveKind.BOOL, 1)
    if td.value == "string":
        return StringType()
    if td.value == "int":
        return PrimitiveType(PrimitiveKind.INT, td.bits)
    return PrimitiveType(PrimitiveKind.UINT, td.bits)  # uint and phandle cells


def _array(element: FieldType, dim: Dim) -> ArrayType:
    lo, hi = dim
    return ArrayType(element, hi, dynamic=hi is None or lo != hi, min_length=lo)


def ir_type(td: TypeDef, shape: Shape) -> FieldType:
    element = element_type(td)
    if shape.outer is None:
        return element
    if shape.inner is None:
        return _array(element, shape.outer)
    return _array(_array(element, shape.inner), shape.outer)


def range_of(schema: Any) -> Range | None:
    if not isinstance(schema, YMap):
        return None
    values = {k: schema.get(k) for k in _RANGE_KEYS}
    nums = {k: v for k, v in values.items() if isinstance(v, int | float) and not isinstance(v, bool)}
    if not nums:
        return None
    lo = nums.get("exclusiveMinimum", nums.get("minimum"))
    hi = nums.get("exclusiveMaximum", nums.get("maximum"))
    return Range(lo, hi, "exclusiveMinimum" in nums, "exclusiveMaximum" in nums)


def as_text(value: Any) -> str:
    """A schema fragment as stable text for annotations."""
    if isinstance(value, str):
        return value
    return json.dumps(value, sort_keys=True, default=str)


@dataclass(frozen=True)
class Values:
    """What a schema says about element values: a range, per-position notes, descriptions."""

    range: Range | None
    notes: tuple[tuple[str, str], ...]
    docs: tuple[str, ...]


def values_of(schema: Any, shape: Shape) -> Values:
    """Constraints on the elements: the property's own min/max, then those in ``items``.

    Per-position items (a row's columns, an array's entries) that differ cannot be one Range;
    they become annotations ``column[i].maximum`` / ``item[i].maximum`` instead.
    """
    own = range_of(schema)
    items = shape.row_schema.get("items") if isinstance(shape.row_schema, YMap) else None
    label = "column" if shape.inner is not None else "item"
    if isinstance(items, YMap):
        return Values(own or range_of(items), (), ())
    if not isinstance(items, list):
        return Values(own, (), ())
    notes: list[tuple[str, str]] = []
    docs: list[str] = []
    ranges = [range_of(i) for i in items]
    for n, item in enumerate(items):
        if not isinstance(item, YMap):
            continue
        if isinstance(item.get("description"), str):
            docs.append(f"[{n}] {' '.join(item['description'].split())}")
        for key, value in item.items():
            if key != "description":
                notes.append((f"{label}[{n}].{key}", as_text(value)))
    shared = ranges[0] if ranges and all(r == ranges[0] for r in ranges) else None
    return Values(own or shared, tuple(notes), tuple(docs))
