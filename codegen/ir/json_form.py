"""The IR's JSON form (``battgen ir``) and the JSON Schema it conforms to.

NaN and the infinities are not JSON numbers, so they are written as the strings ``"NaN"``,
``"Infinity"`` and ``"-Infinity"``; everything else maps one to one.
"""

from __future__ import annotations

import dataclasses
import enum
import json
from functools import cache
from typing import Any

from .. import ir
from .mapping_json import rule_json
from .numbers import to_json_number

# The members of the FieldType union carry a "form" tag so the JSON form is self-describing.
_TYPE_TAGS: dict[type, str] = {
    ir.PrimitiveType: "primitive",
    ir.ArrayType: "array",
    ir.StringType: "string",
    ir.CompositeType: "composite",
}


def to_jsonable(obj: object) -> Any:
    """Turn an IR object (or tuple of them) into plain JSON data."""
    if isinstance(obj, enum.Enum):
        return obj.value
    if isinstance(obj, bool) or obj is None or isinstance(obj, (int, str)):
        return obj
    if isinstance(obj, float):
        return to_json_number(obj)
    if isinstance(obj, tuple | list):
        return [to_jsonable(item) for item in obj]
    if isinstance(obj, ir.Rule):  # a typed op, written as its mapping file spelled it
        return rule_json(obj, to_jsonable)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out: dict[str, Any] = {}
        tag = _TYPE_TAGS.get(type(obj))
        if tag is not None:
            out["form"] = tag
        for f in dataclasses.fields(obj):
            if f.metadata.get("json_form", True):  # parsed forms (rule expressions) show as their text
                out[f.name] = to_jsonable(getattr(obj, f.name))
        if isinstance(obj, ir.PrimitiveType):
            out["name"] = obj.name
        return out
    raise TypeError(f"not an IR value: {type(obj).__name__}")


def schema_to_json(schema: ir.Schema) -> dict[str, Any]:
    data: dict[str, Any] = to_jsonable(schema)
    data["$schema"] = IR_SCHEMA_ID
    return data


def dumps(schema: ir.Schema) -> str:
    """Deterministic JSON text of a schema's IR."""
    return json.dumps(schema_to_json(schema), indent=2, ensure_ascii=False, allow_nan=False) + "\n"


IR_SCHEMA_ID = "https://battgen.dev/schemas/ir.schema.json"


@cache
def ir_json_schema() -> dict[str, Any]:
    """The JSON Schema (Draft 2020-12) of the IR's JSON form, shipped with the toolchain."""
    from importlib import resources  # here: it brings tempfile, which reading data does without

    text = resources.files(__package__).joinpath("ir.schema.json").read_text(encoding="utf-8")
    result: dict[str, Any] = json.loads(text)
    return result


def validate_ir_json(data: dict[str, Any]) -> list[str]:
    """Every way ``data`` departs from the IR schema, as 'path: message' lines (empty when valid)."""
    import jsonschema

    validator = jsonschema.Draft202012Validator(ir_json_schema())
    errors = sorted(validator.iter_errors(data), key=lambda e: list(e.absolute_path))
    return [f"{'/'.join(str(p) for p in e.absolute_path) or '<root>'}: {e.message}" for e in errors]
