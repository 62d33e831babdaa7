"""Rule parameters, read from the op classes: what a mapping file may write for each op.

The fields of each op of :mod:`codegen.ir.ops` and their annotations say everything: which keys
a rule of that op takes, which it needs, and what each holds. This module turns that into the
JSON Schema fragment checking a rule's parameters (:func:`params_schema`) and turns a checked
rule's YAML values into the typed op (:func:`build_op`). A new op or parameter needs no change
here unless it uses a kind of value not listed in :func:`_kind`.
"""

from __future__ import annotations

import enum
import math
import types
from dataclasses import MISSING, Field, fields
from typing import Any, Union, get_args, get_origin, get_type_hints

from ...errors import SchemaError
from ...ir import units
from ...ir.mapping_values import ConstantRef, Entry, UnitSymbol
from ...ir.ops import MappingOp
from ...text.yaml_lines import YMap

# the keys of a rule that are not parameters of its op
RULE_KEYS = ("op", "to", "from", "doc", "only")

# "unknown:" markers may spell NaN and the infinities as text (YAML has no plain NaN literal)
_NON_FINITE = {"nan": math.nan, "infinity": math.inf, "inf": math.inf, "-infinity": -math.inf, "-inf": -math.inf}
_NON_FINITE_PATTERN = "^([Nn][Aa][Nn]|-?[Ii][Nn][Ff]([Ii][Nn][Ii][Tt][Yy])?)$"

_NUMBER = frozenset({int, float})
_VALUE = frozenset({int, float, bool, str, ConstantRef})


def _split_optional(tp: Any) -> tuple[Any, bool]:
    """(the annotation without None, whether None is part of it); unions of several types are frozensets."""
    if isinstance(tp, types.UnionType) or get_origin(tp) is Union:
        members = [a for a in get_args(tp) if a is not type(None)]
        core: Any = members[0] if len(members) == 1 else frozenset(members)
        return core, len(members) != len(get_args(tp))
    return tp, False


def _kind(tp: Any) -> str:
    """The kind of value an annotation (without None) stands for."""
    if tp == _NUMBER:
        return "number"
    if tp == _VALUE:
        return "value"
    if tp is ConstantRef:
        return "constant"
    if tp is UnitSymbol:
        return "unit"
    if tp is str:
        return "text"
    if tp is bool:
        return "bool"
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        return "enum"
    if get_origin(tp) is tuple:
        item, _ = _split_optional(get_args(tp)[0])
        if item == _NUMBER:
            return "markers"
        if isinstance(item, type) and issubclass(item, Entry):
            return "entries"
    raise TypeError(f"no parameter kind for {tp!r}")  # a new kind of op parameter: add it here


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    """The resolved annotations of a dataclass (ops.py defers them as text)."""
    if cls not in _HINTS:
        _HINTS[cls] = get_type_hints(cls)
    return _HINTS[cls]


def _params(cls: type) -> list[tuple[Field[Any], Any, bool]]:
    """(field, annotation without None, whether the field must be written) of an op or entry."""
    out = []
    for f in fields(cls):
        core, _ = _split_optional(_hints(cls)[f.name])
        out.append((f, core, f.default is MISSING and f.default_factory is MISSING))
    return out


# -- JSON Schema ------------------------------------------------------------------------------

_SCHEMAS: dict[str, dict[str, Any]] = {
    "number": {"type": "number"},
    "value": {"type": ["boolean", "number", "string"]},
    "constant": {"type": "string", "minLength": 1},
    "unit": {"type": "string", "minLength": 1},
    "text": {"type": "string"},
    "bool": {"type": "boolean"},
    "markers": {
        "type": "array",
        "items": {"anyOf": [{"type": "number"}, {"type": "string", "pattern": _NON_FINITE_PATTERN}]},
    },
}


def _schema(tp: Any, nullable: bool) -> dict[str, Any]:
    kind = _kind(tp)
    if kind == "entries":
        (entry,) = get_args(tp)[:1]
        _, *rest = _params(entry)
        if len(rest) == 1:
            value = _value_schema(entry, rest[0])
        else:
            value = {
                "type": "object",
                "additionalProperties": False,
                "required": [f.name for f, _, required in rest if required],
                "properties": {f.name: _value_schema(entry, (f, core, r)) for f, core, r in rest},
            }
        return {"type": "object", "additionalProperties": value}
    schema: dict[str, Any] = _SCHEMAS[kind] if kind in _SCHEMAS else {"enum": [m.value for m in tp]}
    if nullable:
        schema = {"anyOf": [schema, {"type": "null"}]}
    return schema


def _value_schema(owner: type, param: tuple[Field[Any], Any, bool]) -> dict[str, Any]:
    f, core, required = param
    # None is written as null only where it is a value of its own, not "left out"
    return _schema(core, required and _split_optional(_hints(owner)[f.name])[1])


def params_schema(cls: type[MappingOp]) -> dict[str, Any]:
    """The JSON Schema of a rule of op ``cls``: its parameters, and the keys every rule has."""
    props: dict[str, Any] = {key: True for key in RULE_KEYS}
    for param in _params(cls):
        props[param[0].name] = _value_schema(cls, param)
    return {
        "required": [f.name for f, _, required in _params(cls) if required],
        "properties": props,
        "additionalProperties": False,
    }


# -- YAML -> typed op --------------------------------------------------------------------------


class _Place:
    """Where a parameter is, for errors."""

    def __init__(self, display: str, line: int, key: str) -> None:
        self.display, self.line, self.key = display, line, key

    def error(self, expected: str, got: object) -> SchemaError:
        return SchemaError(self.display, self.line, f"expected {expected} for {self.key!r}, got {got!r}")


def _number(value: Any, at: _Place) -> int | float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise at.error("a number", value)
    return math.nan if math.isnan(value) else value  # one NaN object, so equal ops compare equal


def _marker(value: Any, at: _Place) -> int | float:
    if isinstance(value, str) and value.lower() in _NON_FINITE:
        return _NON_FINITE[value.lower()]
    return _number(value, at)


def _value(value: Any, at: _Place) -> int | float | bool | str | ConstantRef:
    if isinstance(value, str):
        if ConstantRef.spelled(value):
            return ConstantRef(value)
        return math.nan if value.lower() == "nan" else value
    if isinstance(value, bool):
        return value
    return _number(value, at)


def _convert(tp: Any, nullable: bool, value: Any, at: _Place) -> Any:
    if value is None and nullable:
        return None
    kind = _kind(tp)
    if kind == "number":
        return _number(value, at)
    if kind == "value":
        return _value(value, at)
    if kind in ("constant", "text", "unit"):
        if not isinstance(value, str):
            raise at.error("text", value)
        if kind == "unit" and units.lookup(value) is None:
            raise at.error("a known unit", value)
        return ConstantRef(value) if kind == "constant" else value
    if kind == "bool":
        if not isinstance(value, bool):
            raise at.error("true or false", value)
        return value
    if kind == "enum":
        try:
            return tp(value)
        except ValueError:
            raise at.error(" or ".join(repr(m.value) for m in tp), value) from None
    if kind == "markers":
        if not isinstance(value, list):
            raise at.error("a list of numbers", value)
        return tuple(_marker(v, at) for v in value)
    (entry,) = get_args(tp)[:1]
    if not isinstance(value, dict):
        raise at.error("a mapping", value)
    return tuple(_entry(entry, str(key), item, at) for key, item in value.items())


def _entry(cls: type[Entry], key: str, value: Any, at: _Place) -> Entry:
    (key_field, key_type, _), *rest = _params(cls)
    args = {key_field.name: _convert(key_type, False, key, at)}
    if len(rest) == 1:
        f, core, required = rest[0]
        args[f.name] = _convert(core, required, value, at)
    else:
        if not isinstance(value, dict):
            raise at.error("a mapping", value)
        for f, core, required in rest:
            if f.name in value:
                args[f.name] = _convert(core, required, value[f.name], at)
            elif required:
                raise at.error(f"a mapping with {f.name!r}", value)
    return cls(**args)


def build_op(cls: type[MappingOp], body: YMap, display: str) -> MappingOp:
    """The typed op of a rule (``body`` already checked against the JSON Schema)."""
    args: dict[str, Any] = {}
    for f, core, required in _params(cls):
        if f.name in body:
            nullable = required and _split_optional(_hints(cls)[f.name])[1]
            args[f.name] = _convert(core, nullable, body[f.name], _Place(display, body.line_of(f.name), f.name))
        elif required:
            raise SchemaError(display, body.line, f"expected {f.name!r} for op {cls.NAME!r}")
    return cls(**args)
