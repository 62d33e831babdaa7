"""Dimensions, IR type and value constraints of a typed dt-schema property.

Dimensions follow dt-schema's rules: an ``items`` list fixes the length to its size unless
minItems/maxItems say otherwise; without ``items``, a lone minItems or maxItems fixes the length;
a unit-suffix property written as a plain number (const/enum/minimum/maximum) is one value; a
unit-suffix matrix written as one flat list is a single row.  A length of (n, n) is a fixed
array (``dynamic=False``); an open upper bound is ``capacity=None``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from ...ir import ArrayType, Column, FieldType, PrimitiveKind, PrimitiveType, Range, StringType
from ...text.yaml_lines import YMap
from .columns import as_text, bounds_of, columns_of, verbatim
from .data import TypeDef

Dim = tuple[int, int | None]  # (min items, max items or None when unbounded)

_INT_KEYS = ("const", "enum", "minimum", "maximum")
__all__ = ["UNKNOWN_TYPE", "Shape", "Values", "as_text", "ir_type", "shape_of", "values_of", "with_columns"]
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


range_of = bounds_of


@dataclass(frozen=True)
class Values:
    """What a schema says about element values: one range for every element, the Columns of
    the property's positions (``outer``) and of a matrix row's (``inner``), and notes for what
    neither can hold."""

    range: Range | None
    notes: tuple[tuple[str, str], ...]
    outer: tuple[Column, ...] = ()
    inner: tuple[Column, ...] = ()

    def with_notes(self, notes: list[tuple[str, str]]) -> Values:
        return replace(self, notes=self.notes + tuple(notes))


def _shared(own: Range | None, every: Range | None) -> Range | None:
    """The property's own bounds narrowed by those its ``items`` mapping gives every element."""
    return every if own is None else own.intersect(every)


def values_of(schema: Any, shape: Shape, display: str) -> Values:
    """Constraints on the elements: the property's own min/max, then those in ``items``.

    An ``items`` mapping bounds every element (the field's range); an ``items`` list gives each
    position its own Column -- of the array itself, or of every row of a matrix.  A matrix
    written as a list of row schemas gets one Column per row (its description), and its rows'
    columns when every row lists the same ones and no row goes unlisted; otherwise those stay
    annotations ``row[i].column[j].<key>``.
    """
    own = range_of(schema)
    if shape.outer is None or not isinstance(shape.row_schema, YMap):
        return Values(own, ())
    notes: list[tuple[str, str]] = []
    if shape.inner is None:  # an array: row_schema is the property itself
        items = shape.row_schema.get("items")
        if isinstance(items, list):
            return Values(own, (), columns_of(items, display, "item", notes)).with_notes(notes)
        return Values(_shared(own, bounds_of(items)), ())
    rows = schema.get("items") if isinstance(schema, YMap) and shape.row_schema is not schema else None
    outer = columns_of(rows, display, "row", notes, bounds=False) if isinstance(rows, list) else ()
    each = [_row(r, display, f"row[{n}].column") for n, r in enumerate(rows)] if isinstance(rows, list) else []
    unlisted = isinstance(rows, list) and (shape.outer[1] is None or shape.outer[1] > len(rows))
    if unlisted or any(_same(e) != _same(each[0]) for e in each):  # rows differ: their columns are notes
        assert isinstance(rows, list)
        kept = [
            verbatim(r.get("items") if isinstance(r, YMap) else None, f"row[{n}].column") for n, r in enumerate(rows)
        ]
        return Values(own, (), outer).with_notes(notes + [n for k in kept for n in k])
    shared, inner, inner_notes = _row(shape.row_schema, display, "column")
    return Values(_shared(own, shared), (), outer, inner).with_notes(notes + inner_notes)


def _row(row: Any, display: str, label: str) -> tuple[Range | None, tuple[Column, ...], list[tuple[str, str]]]:
    """A row schema's bounds for every element, its columns, and the notes they leave."""
    items = row.get("items") if isinstance(row, YMap) else None
    notes: list[tuple[str, str]] = []
    if isinstance(items, list):
        return None, columns_of(items, display, label, notes), notes
    return bounds_of(items), (), notes


def _same(row: tuple[Range | None, tuple[Column, ...], list[tuple[str, str]]]) -> object:
    """What two rows must share for one row type to hold both (source lines and labels aside)."""
    bounds, columns, notes = row
    return bounds, [replace(c, location=None) for c in columns], [(t.split("]", 1)[-1], v) for t, v in notes]


def with_columns(t: FieldType, values: Values) -> FieldType:
    """The IR type with the Columns attached at their depth."""
    if not isinstance(t, ArrayType):
        return t
    element = t.element
    if values.inner and isinstance(element, ArrayType):
        element = replace(element, columns=values.inner)
    return replace(t, element=element, columns=values.outer)
