"""The JSON Schema of a mapping file: ``mappings.schema.json`` plus what the op classes say.

The file holds everything but the ops; loading fills in the ``op`` enum and one ``if``/``then``
per op (its parameters, from :mod:`.op_params`), so the op list is written only in
:mod:`codegen.ir.ops`.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

from ...ir.ops import OPS
from .op_params import params_schema


@cache
def mappings_json_schema() -> dict[str, Any]:
    """The complete JSON Schema (Draft 2020-12) every mapping file is checked against."""
    text = resources.files(__package__).joinpath("mappings.schema.json").read_text(encoding="utf-8")
    schema: dict[str, Any] = json.loads(text)
    rule = schema["$defs"]["rule"]
    rule["properties"]["op"] = {"enum": list(OPS)}
    rule["allOf"] = [
        {"if": {"required": ["op"], "properties": {"op": {"const": name}}}, "then": params_schema(cls)}
        for name, cls in OPS.items()
    ]
    return schema
