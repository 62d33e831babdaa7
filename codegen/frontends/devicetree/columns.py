"""Per-position constraints of a dt-schema ``items`` list -> IR Columns.

An ``items`` list (Draft 2020-12's ``prefixItems``) says what each position holds: a table row's
(OCV, percent), a range's (minimum, maximum). Each entry becomes a :class:`~codegen.ir.Column`:
its description, and the numeric bounds a Range can hold -- minimum/maximum (exclusive or not),
a numeric ``const`` (a one-value range) and an integer ``enum`` without gaps. Anything else (a
string const, an enum with gaps, a pattern...) stays an annotation ``<label>[i].<key>``.
"""

from __future__ import annotations

import json
from typing import Any

from ...ir import Column, Location, Range
from ...text.yaml_lines import YMap

_BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
_SIZE_KEYS = frozenset({"items", "minItems", "maxItems"})  # a row's own shape: read by the caller
Notes = list[tuple[str, str]]


def as_text(value: Any) -> str:
    """A schema fragment as stable text for annotations."""
    if isinstance(value, str):
        return value
    return json.dumps(_string_keys(value), sort_keys=True, default=str)


def _string_keys(value: Any) -> Any:
    """YAML allows keys of any type (``3: lithium-ion``); JSON text, and sorting, need strings."""
    if isinstance(value, dict):
        return {str(k): _string_keys(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_string_keys(v) for v in value]
    return value


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def bounds_of(schema: Any) -> Range | None:
    """minimum/maximum/exclusiveMinimum/exclusiveMaximum of a schema, or None."""
    if not isinstance(schema, YMap):
        return None
    nums = {k: schema[k] for k in _BOUNDS if _number(schema.get(k))}
    if not nums:
        return None
    lo = nums.get("exclusiveMinimum", nums.get("minimum"))
    hi = nums.get("exclusiveMaximum", nums.get("maximum"))
    return Range(lo, hi, "exclusiveMinimum" in nums, "exclusiveMaximum" in nums)


def _as_range(key: str, value: Any) -> Range | None:
    """A const or enum as a Range, when one can say it exactly."""
    if key == "const" and _number(value):
        return Range(value, value)
    if key != "enum" or not isinstance(value, list) or not value or not all(_number(v) for v in value):
        return None
    if len(set(value)) == 1:
        return Range(value[0], value[0])
    if all(isinstance(v, int) for v in value):
        lo, hi = min(value), max(value)
        if set(value) == set(range(lo, hi + 1)):
            return Range(lo, hi)
    return None


def column_of(item: Any, display: str, label: str, notes: Notes, *, bounds: bool = True) -> Column:
    """One position's Column; what it cannot hold goes to ``notes`` as ``(label.key, text)``.

    ``bounds`` False for a matrix row: minimum/maximum beside a row's ``items`` bound nothing in
    JSON Schema (the row is an array), so they are kept as notes, not as a range."""
    if not isinstance(item, YMap):
        return Column()
    description = item.get("description")
    doc = " ".join(description.split()) if isinstance(description, str) else ""
    rng = bounds_of(item) if bounds else None
    for key in sorted(item.keys(), key=str):
        value = item[key]
        if key == "description" or key in _SIZE_KEYS or (bounds and key in _BOUNDS and _number(value)):
            continue
        exact = _as_range(str(key), value) if bounds else None
        if exact is not None:
            rng = exact.intersect(rng)
            continue
        notes.append((f"{label}.{key}", as_text(value)))
    return Column(doc=doc, range=rng, location=Location(display, item.line))


def columns_of(items: list[Any], display: str, label: str, notes: Notes, *, bounds: bool = True) -> tuple[Column, ...]:
    """The Columns of an ``items`` list, trailing positions that say nothing left out."""
    found = [column_of(item, display, f"{label}[{n}]", notes, bounds=bounds) for n, item in enumerate(items)]
    while found and _says_nothing(found[-1]):
        found.pop()
    return tuple(found)


def verbatim(items: Any, label: str) -> Notes:
    """Every key of every position, as notes (for positions no Column can hold)."""
    out: Notes = []
    for n, item in enumerate(items if isinstance(items, list) else ()):
        if isinstance(item, YMap):
            out += [(f"{label}[{n}].{key}", as_text(item[key])) for key in sorted(item.keys(), key=str)]
    return out


def _says_nothing(c: Column) -> bool:
    return not c.doc and c.unit is None and c.range is None
