"""A fast yes/no check of a mapping file against the mappings JSON Schema, for the bundled files.

jsonschema walks a rule through one ``if``/``then`` per op, building a new validator object per
node and a generator per keyword; over the bundled files that is most of every command's start-up.
This module compiles the same JSON Schema (:func:`.json_schema.mappings_json_schema`, so the op list
and parameters still come from the op classes) once into plain Python predicates, each keyword with
jsonschema's Draft 2020-12 meaning, and answers only "valid or not". A file it does not accept is
handed to jsonschema for the error, so the message is jsonschema's, word for word.

Only the keywords the mappings schema uses are known; any other keyword makes compiling fail
(:class:`TypeError`) rather than be ignored, so a schema change cannot quietly weaken the check.
``tests/frontends/test_mapping_fast_check.py`` proves it agrees with jsonschema on every bundled
mapping file, on the error fixtures and on mutations of each bundled file.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from functools import cache
from typing import Any

from .json_schema import mappings_json_schema

Check = Callable[[Any], bool]

# keywords that say nothing about an instance
_ANNOTATIONS = frozenset({"$schema", "$id", "$comment", "$defs", "title", "description"})


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _is_integer(value: Any) -> bool:
    if isinstance(value, bool):
        return False
    return isinstance(value, int) or (isinstance(value, float) and math.isfinite(value) and value.is_integer())


_TYPES: dict[str, Check] = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "number": _is_number,
    "integer": _is_integer,
    "boolean": lambda v: isinstance(v, bool),
    "null": lambda v: v is None,
}


def _equal(a: Any, b: Any) -> bool:
    """JSON equality as jsonschema has it: true and 1 differ, 1 and 1.0 do not."""
    if isinstance(a, bool) or isinstance(b, bool):
        return isinstance(a, bool) and isinstance(b, bool) and a == b
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def _all(checks: Sequence[Check]) -> Check:
    if len(checks) == 1:
        return checks[0]
    return lambda v: all(c(v) for c in checks)


class _Compiler:
    def __init__(self, root: dict[str, Any]) -> None:
        self.root = root
        self.refs: dict[str, Check] = {}

    def ref(self, pointer: str) -> Check:
        if pointer not in self.refs:
            if not pointer.startswith("#/$defs/"):
                raise TypeError(f"only local $defs references are compiled, got {pointer!r}")
            self.refs[pointer] = lambda v: self.refs[pointer + "!"](v)  # recursion-safe until compiled
            self.refs[pointer + "!"] = self.compile(self.root["$defs"][pointer.removeprefix("#/$defs/")])
        return self.refs[pointer]

    def compile(self, schema: bool | dict[str, Any]) -> Check:
        if schema is True:
            return lambda v: True
        if schema is False:
            return lambda v: False
        checks: list[Check] = []
        for key, arg in schema.items():
            if key in _ANNOTATIONS or key == "then":  # "then" is compiled with its "if"
                continue
            checks.append(self.keyword(key, arg, schema))
        return _all(checks) if checks else (lambda v: True)

    def keyword(self, key: str, arg: Any, schema: dict[str, Any]) -> Check:
        if key == "type":
            names = [arg] if isinstance(arg, str) else list(arg)
            tests = [_TYPES[n] for n in names]
            return lambda v: any(t(v) for t in tests)
        if key == "enum":
            return lambda v: any(_equal(v, e) for e in arg)
        if key == "const":
            return lambda v: _equal(v, arg)
        if key == "pattern":
            search = re.compile(arg).search
            return lambda v: not isinstance(v, str) or search(v) is not None
        if key == "minLength":
            return lambda v: not isinstance(v, str) or len(v) >= arg
        if key == "minItems":
            return lambda v: not isinstance(v, list) or len(v) >= arg
        if key == "minProperties":
            return lambda v: not isinstance(v, dict) or len(v) >= arg
        if key == "uniqueItems":
            if not arg:
                return lambda v: True
            return lambda v: (
                not isinstance(v, list) or not any(_equal(v[i], v[j]) for i in range(len(v)) for j in range(i))
            )
        if key == "required":
            names = list(arg)
            return lambda v: not isinstance(v, dict) or all(n in v for n in names)
        if key == "properties":
            props = {name: self.compile(sub) for name, sub in arg.items()}
            return lambda v: not isinstance(v, dict) or all(c(v[n]) for n, c in props.items() if n in v)
        if key == "additionalProperties":
            known = frozenset(schema.get("properties", {}))
            if "patternProperties" in schema:
                raise TypeError("patternProperties is not compiled")
            extra = self.compile(arg)
            return lambda v: not isinstance(v, dict) or all(extra(v[k]) for k in v if k not in known)
        if key == "propertyNames":
            names_ok = self.compile(arg)
            return lambda v: not isinstance(v, dict) or all(names_ok(k) for k in v)
        if key == "items":
            item = self.compile(arg)
            return lambda v: not isinstance(v, list) or all(item(x) for x in v)
        if key == "$ref":
            return self.ref(arg)
        if key == "allOf":
            return self.dispatch(arg) or _all([self.compile(s) for s in arg])
        if key == "anyOf":
            anyof = [self.compile(s) for s in arg]
            return lambda v: any(c(v) for c in anyof)
        if key == "oneOf":
            oneof = [self.compile(s) for s in arg]
            return lambda v: sum(1 for c in oneof if c(v)) == 1
        if key == "if":
            cond, then = self.compile(arg), self.compile(schema.get("then", True))
            return lambda v: not cond(v) or then(v)
        raise TypeError(f"JSON Schema keyword {key!r} is not compiled")  # a new keyword: add it here

    def dispatch(self, branches: list[Any]) -> Check | None:
        """An ``allOf`` of ``if {KEY: const C} then S`` (a rule's op parameters) as one look-up of
        ``KEY``: on an object at most one ``if`` holds, since the constants differ; the same
        verdict as trying every branch, without trying them."""
        keys: set[str] = set()
        cases: dict[str, Check] = {}
        for b in branches:
            cond = b.get("if", {}) if isinstance(b, dict) and set(b) == {"if", "then"} else {}
            props = cond.get("properties", {})
            if set(cond) != {"required", "properties"} or len(props) != 1 or cond["required"] != list(props):
                return None
            [(key, want)] = props.items()
            if set(want) != {"const"} or not isinstance(want["const"], str) or want["const"] in cases:
                return None
            keys.add(key)
            cases[want["const"]] = self.compile(b["then"])
        if len(keys) != 1:
            return None
        key = keys.pop()
        every = _all(list(cases.values()))  # not an object: every "if" holds (its keywords ignore it)

        def check(v: Any) -> bool:
            if not isinstance(v, dict):
                return every(v)
            chosen = v.get(key)
            then = cases.get(chosen) if isinstance(chosen, str) else None
            return then is None or then(v)

        return check


@cache
def mapping_file_check() -> Check:
    """Whether a loaded mapping file is valid against :func:`.json_schema.mappings_json_schema`."""
    schema = mappings_json_schema()
    return _Compiler(schema).compile(schema)
