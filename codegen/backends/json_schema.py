"""JSON Schema (Draft 2020-12) export of messages, agreeing with the generated ``from_dict`` +
``validate()`` on plain JSON data.

Decisions (the conformance test ``conformance/test_jsonschema_agreement.py`` holds us to them):

- NaN and the infinities are JSON strings: ``"NaN"``, ``"Infinity"``, ``"-Infinity"`` (as in the
  IR JSON); the generated reader also takes ``"nan"``, ``"inf"``, ``"-inf"``, so the schema accepts
  those spellings too. A string is accepted only where the value is allowed: NaN where NaN is the
  field's "unknown" sentinel, an infinity where the schema's range reaches it.
- Sentinels validate: a field whose sentinel lies outside its range is ``anyOf [range, const]``.
- Type widths become ``minimum``/``maximum`` (float16 at ±65504, float32 at ±3.4028235e38, finite);
  arrays get ``minItems``/``maxItems``; value enums are ``enum``; a bitmask whose allowed bits are the
  low ones (reserved bits lie above) is a ``maximum``, low bits plus a few high ones an ``anyOf`` of
  ranges (one per combination of the high bits), any other mask an ``enum`` of its combinations (up
  to 4096); beyond that it is left to the generated validator.
- Absent fields take their defaults in ``from_dict``; a field whose default is not valid (uORB
  ``max_error`` = 0 against its range 1..100) is therefore ``required``, as are devicetree
  ``required`` properties.
- Not expressed: cross-field rules (schemas/rules/, listed in ``$comment``), and UTF-8 byte lengths
  -- a byte array given as text is accepted only as ASCII (``maxLength`` counts characters); give
  other text as a list of byte values.
- bool fields take ``true``/``false`` and the integers 0 and 1 (as the reader does).
- Per-position constraints (``ArrayType.columns``: an OCV table row's percent column) are
  ``prefixItems``, each entry the element's schema narrowed by its column (``items`` covers the
  positions after them); a byte array with a bounded column is accepted only as a list.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ..ir import (
    ArrayType,
    Column,
    CompositeType,
    EnumKind,
    Field,
    FieldType,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
    Sentinel,
    StringType,
)
from ..ir.fieldtypes import allowed_range
from ..ir.numbers import INFINITY_SPELLINGS, NAN_SPELLINGS, NEG_INFINITY_SPELLINGS
from ..ir.rules import rules_for

DRAFT = "https://json-schema.org/draft/2020-12/schema"
NAN_STRINGS = list(NAN_SPELLINGS)
INF_STRINGS = list(INFINITY_SPELLINGS)
NEG_INF_STRINGS = list(NEG_INFINITY_SPELLINGS)
_MAX_MASK_ENUM = 4096


def export_all(schema: Schema) -> dict[str, dict[str, Any]]:
    """Every message's JSON Schema, by qualified name."""
    return {m.qualified_name: message_json_schema(schema, m) for m in schema.messages}


def message_json_schema(schema: Schema, msg: Message) -> dict[str, Any]:
    defs: dict[str, dict[str, Any]] = {}
    body = _object(schema, msg, defs)
    out: dict[str, Any] = {
        "$schema": DRAFT,
        "$id": f"urn:battgen:{msg.qualified_name}",
        "title": msg.qualified_name,
    }
    out.update(body)
    rules = rules_for(schema, msg)
    if rules:
        out["$comment"] = "Cross-field rules checked by the generated validate() but not expressed here: " + "; ".join(
            f"{r.id} ({r.check})" for r in rules
        )
    if defs:
        out["$defs"] = dict(sorted(defs.items()))
    return out


def _object(schema: Schema, msg: Message, defs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    src = msg.location
    doc = msg.doc.strip() + "\n\n" if msg.doc.strip() else ""
    doc += f"Schema: {msg.qualified_name} ({src.file}:{src.line})."
    props: dict[str, Any] = {}
    patterns: dict[str, Any] = {}
    required: list[str] = []
    for f in msg.fields:
        if f.is_padding:
            continue
        node = _field(schema, f, defs)
        if f.pattern is not None:
            patterns[f.pattern] = node
            continue
        props[f.name] = node
        if f.required or (msg.devicetree is None and not _default_ok(schema, f, f.type, top=True)):
            required.append(f.name)
    out: dict[str, Any] = {"description": doc, "type": "object", "properties": props}
    if patterns:
        out["patternProperties"] = patterns
    out["additionalProperties"] = False
    if required:
        out["required"] = required
    if msg.is_union:
        _union(out, list(props))
    return out


def _union(out: dict[str, Any], branches: list[str]) -> None:
    """A DroneCAN union's plain data holds one branch: its key alone, or with ``union_field`` naming it."""
    out["properties"]["union_field"] = {"description": "The branch this union holds.", "enum": branches}
    out.pop("required", None)  # no branch is required: the empty object holds the first at its default
    named = [
        {
            "required": ["union_field"],
            "properties": {"union_field": {"const": b}},
            "propertyNames": {"enum": ["union_field", b]},
        }
        for b in branches
    ]
    out["anyOf"] = [*named, {"not": {"required": ["union_field"]}, "maxProperties": 1}]


def _description(f: Field) -> str:
    doc = f.doc.strip()
    parts = [doc if not doc or doc.endswith((".", "!", "?", ":")) else doc + "."]
    if f.unit is not None:
        parts.append(f"Unit: {f.unit.symbol}.")
    elif f.unit_text:
        parts.append(f"Unit: {f.unit_text}.")
    s = f.invalid
    if s is not None:
        each = " (per element)" if s.per_element or isinstance(f.type, ArrayType) else ""
        if s.elements:
            each = " (by position)"
        if s.first_decides:
            each = " (the whole array, when its first element holds it)"
        value = "NaN" if s.is_nan else repr(s.value)
        named = "" if s.text.strip("[]") in (value, "NaN") else f" ({s.text.strip('[]')})"
        parts.append(f"Unknown{each}: {value}{named}, accepted as a valid value.")
    return " ".join(p for p in parts if p)


def _field(schema: Schema, f: Field, defs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    node = _type(schema, f, f.type, defs)
    text = _description(f)
    if text:
        node = {"description": text, **node} if "$ref" not in node else {"description": text, "allOf": [node]}
    if f.unit is not None:
        node["x-unit"] = f.unit.symbol
    return node


def _type(schema: Schema, f: Field, t: FieldType, defs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    if isinstance(t, PrimitiveType):
        return _number(schema, f, t)
    if isinstance(t, StringType):
        node: dict[str, Any] = {"type": "string"}
        if t.capacity is not None:
            node["maxLength"] = t.capacity
        if isinstance(f.const, str):
            node["const"] = f.const
        elif f.choices:
            node["enum"] = [str(c) for c in f.choices]
        return node
    if isinstance(t, CompositeType):
        if t.name not in defs:
            defs[t.name] = {}  # placeholder against cycles
            defs[t.name] = _object(schema, schema.message(t.name), defs)
        return {"$ref": f"#/$defs/{t.name}"}
    items = _type(schema, f, t.element, defs)
    node = {"type": "array", "items": items}
    if t.columns:
        node["prefixItems"] = [_column(schema, f, c, t.element, defs) for c in t.columns]
    if not t.dynamic and t.capacity is not None:
        node["minItems"] = node["maxItems"] = t.capacity
    else:
        if t.min_length:
            node["minItems"] = t.min_length
        if t.capacity is not None:
            node["maxItems"] = t.capacity
    el = t.element
    bounded = any(c.range is not None for c in t.columns)
    if isinstance(el, PrimitiveType) and el.kind is PrimitiveKind.UINT and el.bits == 8 and not bounded:
        text: dict[str, Any] = {"type": "string", "pattern": r"^[\x00-\x7f]*$"}
        if t.capacity is not None:
            text["maxLength"] = t.capacity
            if not t.dynamic:
                text["minLength"] = t.capacity
        elif t.min_length:
            text["minLength"] = t.min_length
        return {"anyOf": [node, text]}
    return node


def at_column(f: Field, c: Column) -> Field:
    """The field as seen at one array position: its column's range on top of its own, its unit."""
    return replace(f, range=c.range.intersect(f.range) if c.range is not None else f.range, unit=c.unit or f.unit)


def _column(schema: Schema, f: Field, c: Column, element: FieldType, defs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    node = _type(schema, at_column(f, c), element, defs)
    if c.doc:
        node = {"description": c.doc, **node} if "$ref" not in node else {"description": c.doc, "allOf": [node]}
    if c.unit is not None:
        node["x-unit"] = c.unit.symbol
    return node


def _bounds(t: PrimitiveType, f: Field) -> tuple[float, float, bool, bool]:
    """Folded type width and schema range: (low, high, low exclusive, high exclusive)."""
    r = allowed_range(t, f.range)
    assert r.minimum is not None and r.maximum is not None
    return r.minimum, r.maximum, r.exclusive_minimum, r.exclusive_maximum


def _enum_facts(schema: Schema, f: Field) -> tuple[list[int] | None, int | None]:
    values: list[int] = []
    mask: int | None = None
    for name in f.enums:
        e = schema.enum(name)
        if e.kind is EnumKind.VALUE:
            values += [x.value for x in e.entries]
            continue
        mask = mask or 0
        for x in e.entries:
            if "RESERVED" not in x.name.upper():
                mask |= x.value if e.kind is EnumKind.BITMASK else 1 << x.value
    if mask is not None:
        return None, mask
    return (sorted(set(values)) if f.enums else None), None


def _number(schema: Schema, f: Field, t: PrimitiveType) -> dict[str, Any]:
    if t.kind is PrimitiveKind.BOOL:
        return {"anyOf": [{"type": "boolean"}, {"type": "integer", "minimum": 0, "maximum": 1}]}
    if t.kind is PrimitiveKind.CHAR:
        return {"type": "string", "maxLength": 1}
    low, high, lo_x, hi_x = _bounds(t, f)
    is_float = t.kind is PrimitiveKind.FLOAT
    core: dict[str, Any] = {"type": "number" if is_float else "integer"}
    if math.isfinite(low):
        core["exclusiveMinimum" if lo_x else "minimum"] = _json_number(low, is_float)
    if math.isfinite(high):
        core["exclusiveMaximum" if hi_x else "maximum"] = _json_number(high, is_float)
    values, mask = _enum_facts(schema, f) if not is_float else (None, None)
    if values is not None:
        core["enum"] = values
    if mask is not None:
        if mask & (mask + 1) == 0:  # the low bits: a maximum says it
            core["maximum"] = min(core.get("maximum", mask), mask)
        elif bin(mask).count("1") <= _MAX_MASK_ENUM.bit_length() - 1:
            core["enum"] = _mask_values(mask)
        elif bin(mask & (mask + 1)).count("1") <= _MAX_MASK_ENUM.bit_length() - 1:
            # low bits plus a few high ones (MAVLink's ..._FLAGS_EXTENDED = 2**31): one range per high combination
            low = mask ^ (mask & (mask + 1))
            core["anyOf"] = [{"minimum": h, "maximum": h | low} for h in _mask_values(mask & (mask + 1))]
    alternatives = [core]
    if is_float and high == math.inf:
        alternatives.append({"enum": INF_STRINGS})
    if is_float and low == -math.inf:
        alternatives.append({"enum": NEG_INF_STRINGS})
    s = _leaf_sentinel(f)
    if s is not None:
        if s.is_nan:
            alternatives.append({"enum": NAN_STRINGS})
        elif not _core_accepts(core, s.value):
            alternatives.append({"const": _json_number(s.value, is_float)})
    return core if len(alternatives) == 1 else {"anyOf": alternatives}


def _json_number(value: float, is_float: bool) -> float | int:
    """The bound as JSON writes it: integral values as integers (exactly, below 2**53)."""
    if isinstance(value, int):
        return value
    return int(value) if value.is_integer() and abs(value) < 2**53 else float(value)


def _mask_values(mask: int) -> list[int]:
    bits = [1 << i for i in range(mask.bit_length()) if mask >> i & 1]
    out = [0]
    for b in bits:
        out += [v | b for v in out]
    return sorted(out)


def _core_accepts(core: dict[str, Any], value: float) -> bool:
    if "minimum" in core and value < core["minimum"]:
        return False
    if "maximum" in core and value > core["maximum"]:
        return False
    if "exclusiveMinimum" in core and value <= core["exclusiveMinimum"]:
        return False
    if "exclusiveMaximum" in core and value >= core["exclusiveMaximum"]:
        return False
    if "anyOf" in core and not any(r["minimum"] <= value <= r["maximum"] for r in core["anyOf"]):
        return False
    return "enum" not in core or value in core["enum"]


def _leaf_sentinel(f: Field) -> Sentinel | None:
    return f.invalid


# --------------------------------------------------------------------------------------------
# Which defaults are valid (a field with an invalid default must be given)


def _default_ok(schema: Schema, f: Field, t: FieldType, *, top: bool = False) -> bool:
    if isinstance(t, PrimitiveType):
        if f.invalid is not None:
            return True  # defaults to its sentinel
        if top and f.const is not None:
            return True
        value = f.default if top and isinstance(f.default, int | float) else 0
        return _leaf_ok(schema, f, t, float(value))
    if isinstance(t, StringType):
        text = f.const if isinstance(f.const, str) else (f.default if isinstance(f.default, str) else "")
        return not f.choices or text in f.choices
    if isinstance(t, CompositeType):
        msg = schema.message(t.name)
        return all(_default_ok(schema, g, g.type, top=True) for g in msg.fields if not g.is_padding)
    if t.dynamic or not t.capacity:
        return t.min_length == 0
    if isinstance(t.element, PrimitiveType) and f.invalid is not None:
        return True  # filled with the sentinel
    columns = t.columns[: t.capacity]
    return _default_ok(schema, f, t.element) and all(_default_ok(schema, at_column(f, c), t.element) for c in columns)


def _leaf_ok(schema: Schema, f: Field, t: PrimitiveType, value: float) -> bool:
    if t.kind in (PrimitiveKind.BOOL, PrimitiveKind.CHAR):
        return True
    low, high, lo_x, hi_x = _bounds(t, f)
    if (value <= low if lo_x else value < low) or (value >= high if hi_x else value > high):
        return False
    values, _ = _enum_facts(schema, f) if t.kind is not PrimitiveKind.FLOAT else (None, None)
    return values is None or value in values
