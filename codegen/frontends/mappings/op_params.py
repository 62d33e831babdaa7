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
from dataclasses import MISSING, dataclass, fields
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


@dataclass(frozen=True)
class _Param:
    """One parameter of an op (or one field of an entry), read from its dataclass field."""

    name: str
    type: Any  # the annotation without None
    required: bool  # no default: a rule must write it
    null: bool  # a required parameter that may be null (None is a value of its own, not "left out")


_PARAMS: dict[type, tuple[_Param, ...]] = {}


def _params(cls: type) -> tuple[_Param, ...]:
    """The parameters of an op, or the fields of an entry, in order."""
    if cls not in _PARAMS:
        hints = get_type_hints(cls)  # ops.py defers its annotations as text
        out = []
        for f in fields(cls):
            core, optional = _split_optional(hints[f.name])
            required = f.default is MISSING and f.default_factory is MISSING
            out.append(_Param(f.name, core, required, required and optional))
        _PARAMS[cls] = tuple(out)
    return _PARAMS[cls]


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


def _schema(param: _Param) -> dict[str, Any]:
    kind = _kind(param.type)
    if kind == "entries":  # a YAML mapping: key -> the entry's one other field, or a mapping of its fields
        _, *rest = _params(get_args(param.type)[0])
        if len(rest) == 1:
            value = _schema(rest[0])
        else:
            value = {
                "type": "object",
                "additionalProperties": False,
                "required": [p.name for p in rest if p.required],
                "properties": {p.name: _schema(p) for p in rest},
            }
        return {"type": "object", "additionalProperties": value, "minProperties": 1}
    schema = _SCHEMAS[kind] if kind in _SCHEMAS else {"enum": [m.value for m in param.type]}
    return {"anyOf": [schema, {"type": "null"}]} if param.null else schema


def params_schema(cls: type[MappingOp]) -> dict[str, Any]:
    """The JSON Schema of a rule of op ``cls``: its parameters, and the keys every rule has."""
    props: dict[str, Any] = {key: True for key in RULE_KEYS}
    props.update({p.name: _schema(p) for p in _params(cls)})
    return {
        "required": [p.name for p in _params(cls) if p.required],
        "properties": props,
        "additionalProperties": False,
    }


# -- YAML -> typed op --------------------------------------------------------------------------


@dataclass(frozen=True)
class _Place:
    """Where a parameter is, for errors."""

    display: str
    line: int
    key: str

    def error(self, expected: str, got: object) -> SchemaError:
        return SchemaError(self.display, self.line, f"expected {expected} for {self.key!r}, got {got!r}")


def _number(value: Any, at: _Place, *, finite: bool = True) -> int | float:
    """A number; a bound, an offset or a threshold must be finite (YAML's .inf and .nan are floats
    too, and would reach the emitters as a bound no integer field can hold)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise at.error("a number", value)
    if finite and isinstance(value, float) and not math.isfinite(value):
        raise at.error("a finite number", value)
    return math.nan if math.isnan(value) else value  # one NaN object, so equal ops compare equal


def _marker(value: Any, at: _Place) -> int | float:
    if isinstance(value, str) and value.lower() in _NON_FINITE:
        return _NON_FINITE[value.lower()]
    return _number(value, at, finite=False)  # an unknown marker may be NaN or an infinity


def _value(value: Any, at: _Place) -> int | float | bool | str | ConstantRef:
    if isinstance(value, str):
        if ConstantRef.spelled(value):
            return ConstantRef(value)
        return math.nan if value.lower() == "nan" else value
    if isinstance(value, bool):
        return value
    if isinstance(value, float) and math.isnan(value):
        return math.nan  # a value written as NaN (a float field's unknown)
    return _number(value, at)


def _convert(param: _Param, value: Any, at: _Place) -> Any:
    if value is None and param.null:
        return None
    tp = param.type
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
    if not isinstance(value, dict) or not value:
        raise at.error("a mapping of at least one entry", value)
    return tuple(_entry(get_args(tp)[0], str(key), item, at) for key, item in value.items())


def _entry(cls: type[Entry], key: str, value: Any, at: _Place) -> Entry:
    key_param, *rest = _params(cls)
    args = {key_param.name: _convert(key_param, key, at)}
    if len(rest) == 1:
        args[rest[0].name] = _convert(rest[0], value, at)
    else:
        if not isinstance(value, dict):
            raise at.error("a mapping", value)
        for p in rest:
            if p.name in value:
                args[p.name] = _convert(p, value[p.name], at)
            elif p.required:
                raise at.error(f"a mapping with {p.name!r}", value)
    return cls(**args)


def build_op(cls: type[MappingOp], body: YMap, display: str) -> MappingOp:
    """The typed op of a rule (``body`` already checked against the JSON Schema)."""
    args: dict[str, Any] = {}
    for p in _params(cls):
        if p.name in body:
            args[p.name] = _convert(p, body[p.name], _Place(display, body.line_of(p.name), p.name))
        elif p.required:
            raise SchemaError(display, body.line, f"expected {p.name!r} for op {cls.NAME!r}")
    return cls(**args)
