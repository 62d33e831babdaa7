"""Frontend for converter mappings (``schemas/mappings/*.yaml``): concepts, endpoints, mappings.

Each file is safe-loaded with line numbers, checked against ``codegen/mappings.schema.json``,
and turned into IR (:class:`~codegen.ir.MappingSet`). Given the formats' Schema, every reference
(message, field, constant, concept, unit) is checked, so a typo is a SchemaError naming the
file and line rather than a broken converter.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import SchemaError
from ..ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Concept,
    Endpoint,
    FieldRef,
    Location,
    Mapping,
    MappingSet,
    Message,
    Param,
    ParamValue,
    Rule,
    Schema,
    units,
)
from ..text.files import display_path, read_text
from ..text.yaml_lines import YMap, line_at, load

# params naming constants of the message a rule reads or writes (checked when formats are known)
_CONSTANT_PARAMS = {"mask", "map", "bits", "default", "equals"}


@cache
def mappings_json_schema() -> dict[str, Any]:
    text = resources.files(__package__).joinpath("mappings.schema.json").read_text(encoding="utf-8")
    result: dict[str, Any] = json.loads(text)
    return result


def _validate(doc: Any, display: str) -> None:
    import jsonschema

    validator = jsonschema.Draft202012Validator(mappings_json_schema())
    errors = sorted(validator.iter_errors(doc), key=lambda e: (len(e.absolute_path), list(map(str, e.absolute_path))))
    if errors:
        err = errors[0]
        best = jsonschema.exceptions.best_match(errors) or err
        path = list(best.absolute_path)
        where = "/".join(str(p) for p in path) or "the top level"
        raise SchemaError(display, line_at(doc, path), f"expected a valid mapping file at {where}: {best.message}")


def _param_value(value: Any) -> ParamValue:
    if isinstance(value, dict):
        return tuple(Param(str(k), _param_value(v)) for k, v in value.items())
    if isinstance(value, list):
        return tuple(_param_value(v) for v in value)
    result: ParamValue = value
    return result


class _Resolver:
    """Resolves names across all files of a folder: concepts, endpoints and (optionally) formats."""

    def __init__(self, schema: Schema | None) -> None:
        self.schema = schema
        self.concepts: dict[str, Concept] = {}
        self.endpoints: dict[str, Endpoint] = {}

    def message(self, name: str, display: str, line: int) -> Message | None:
        if self.schema is None:
            return None
        try:
            return self.schema.message(name)
        except KeyError:
            raise SchemaError(display, line, f"expected a known message, got {name!r}") from None

    def endpoint(self, name: str, display: str, line: int) -> Endpoint | None:
        if name == CONCEPTS_ENDPOINT:
            return None
        found = self.endpoints.get(name)
        if found is None:
            known = ", ".join([*sorted(self.endpoints), CONCEPTS_ENDPOINT])
            raise SchemaError(display, line, f"expected a declared endpoint ({known}), got {name!r}")
        return found

    def ref(self, text: str, endpoint: Endpoint | None, display: str, line: int) -> FieldRef:
        if endpoint is None:
            if text not in self.concepts:
                raise SchemaError(display, line, f"expected a declared concept, got {text!r}")
            return FieldRef(CONCEPTS_ENDPOINT, text)
        aliases = dict(zip(endpoint.aliases, endpoint.messages, strict=True))
        if text in aliases:
            return FieldRef(aliases[text], "")
        alias, dot, field = text.partition(".")
        if dot and alias in aliases:
            qualified = aliases[alias]
        elif len(aliases) == 1:
            qualified, field = endpoint.messages[0], text
        else:
            known = ", ".join(endpoint.aliases)
            raise SchemaError(display, line, f"expected ALIAS.FIELD with ALIAS one of {known}, got {text!r}")
        msg = self.message(qualified, display, line)
        if msg is not None and not any(f.name == field for f in msg.fields):
            raise SchemaError(display, line, f"expected a field of {qualified}, got {field!r}")
        return FieldRef(qualified, field)


def _concepts(doc: YMap, display: str) -> list[Concept]:
    out = []
    for name, body in doc.get("concepts", {}).items():
        line = doc["concepts"].line_of(name)
        unit = None
        if "unit" in body:
            unit = units.lookup(body["unit"])
            if unit is None:
                raise SchemaError(display, body.line_of("unit"), f"expected a known unit, got {body['unit']!r}")
        kind = body["kind"]
        choices = tuple(body.get("choices", ()))
        if kind in ("choice", "flags") and not choices:
            raise SchemaError(display, line, f"expected choices for a {kind} concept")
        out.append(Concept(name, kind, unit, body.get("doc", "").strip(), choices, Location(display, line)))
    return out


def _endpoints(doc: YMap, display: str, resolver: _Resolver) -> list[Endpoint]:
    out = []
    for name, body in doc.get("endpoints", {}).items():
        line = doc["endpoints"].line_of(name)
        if name == CONCEPTS_ENDPOINT:
            raise SchemaError(display, line, f"expected an endpoint name other than the built-in {name!r}")
        messages = body["messages"]
        for alias, qualified in messages.items():
            resolver.message(qualified, display, messages.line_of(alias))
        out.append(
            Endpoint(
                name,
                tuple(messages.values()),
                tuple(messages.keys()),
                body.get("doc", "").strip(),
                Location(display, line),
            )
        )
    return out


def _refs(value: Any) -> list[str]:
    return [value] if isinstance(value, str) else list(value)


def _check_constants(rule: Rule, resolver: _Resolver, display: str, line: int) -> None:
    """Constant names in params (``mask: STATUS_FLAG_IN_USE``) must exist on a message the rule uses."""
    if resolver.schema is None:
        return
    names: set[str] = set()
    for ref in rule.targets + rule.sources:
        if ref.message != CONCEPTS_ENDPOINT:
            msg = resolver.schema.message(ref.message)
            names.update(c.name for c in msg.constants)
    for e in resolver.schema.enums:
        names.update(x.name for x in e.entries)

    def walk(value: ParamValue | Param, key: str) -> None:
        if isinstance(value, Param):
            if key in ("map", "bits") and value.name.isupper() and value.name not in names:
                raise SchemaError(display, line, f"expected a constant of the messages used, got {value.name!r}")
            walk(value.value, value.name if key in ("map", "bits") else key)
        elif isinstance(value, tuple):
            for item in value:
                walk(item, key)
        elif isinstance(value, str) and value.isupper() and key in _CONSTANT_PARAMS and value not in names:
            raise SchemaError(display, line, f"expected a constant of the messages used, got {value!r}")

    for p in rule.params:
        walk(p.value, p.name)


def _mappings(doc: YMap, display: str, resolver: _Resolver) -> list[Mapping]:
    out = []
    for body in doc.get("mappings", []):
        line = body.line
        source = resolver.endpoint(body["source"], display, body.line_of("source"))
        target = resolver.endpoint(body["target"], display, body.line_of("target"))
        rules = []
        for rbody in body["rules"]:
            rline = rbody.line
            targets = tuple(resolver.ref(r, target, display, rbody.line_of("to")) for r in _refs(rbody["to"]))
            sources = tuple(
                resolver.ref(r, source, display, rbody.line_of("from")) for r in _refs(rbody.get("from", []))
            )
            params = tuple(Param(k, _param_value(v)) for k, v in rbody.items() if k not in ("op", "to", "from", "doc"))
            rule = Rule(rbody["op"], targets, sources, params, rbody.get("doc", "").strip(), Location(display, rline))
            _check_constants(rule, resolver, display, rline)
            if rule.op == "cells" and resolver.schema is not None:
                _check_arrays(rule, resolver.schema, display, rline)
            rules.append(rule)
        out.append(
            Mapping(
                name=body["name"],
                source=body["source"],
                target=body["target"],
                policy=body.get("policy", "strict"),
                rules=tuple(rules),
                reversible=bool(body.get("reversible", False)),
                doc=body.get("doc", "").strip(),
                location=Location(display, line),
            )
        )
    return out


def _check_arrays(rule: Rule, schema: Schema, display: str, line: int) -> None:
    for ref in rule.targets + rule.sources:
        if ref.message != CONCEPTS_ENDPOINT and not isinstance(
            schema.message(ref.message).field(ref.field).type, ArrayType
        ):
            raise SchemaError(display, line, f"expected an array field for op 'cells', got {ref.field!r}")


def _load(path: Path, root: Path | None) -> tuple[str, YMap]:
    display = display_path(path, root)
    doc = load(read_text(path, display), display)
    if not isinstance(doc, YMap):
        raise SchemaError(display, getattr(doc, "line", 1) or 1, "expected a mapping file (a YAML mapping)")
    _validate(doc, display)
    return display, doc


def _parse(paths: list[Path], root: Path | None, schema: Schema | None) -> Schema:
    resolver = _Resolver(schema)
    loaded = [_load(p, root) for p in paths]
    sets: dict[str, dict[str, list[Any]]] = {d: {"concepts": [], "endpoints": [], "mappings": []} for d, _ in loaded}
    for display, doc in loaded:  # declarations first: any file may use any file's concepts
        for c in _concepts(doc, display):
            if c.name in resolver.concepts:
                raise SchemaError(
                    display, c.location.line if c.location else 1, f"concept {c.name!r} is declared twice"
                )
            resolver.concepts[c.name] = c
            sets[display]["concepts"].append(c)
        for e in _endpoints(doc, display, resolver):
            if e.name in resolver.endpoints:
                raise SchemaError(
                    display, e.location.line if e.location else 1, f"endpoint {e.name!r} is declared twice"
                )
            resolver.endpoints[e.name] = e
            sets[display]["endpoints"].append(e)
    names: set[str] = set()
    for display, doc in loaded:
        for m in _mappings(doc, display, resolver):
            if m.name in names:
                raise SchemaError(
                    display, m.location.line if m.location else 1, f"mapping {m.name!r} is declared twice"
                )
            names.add(m.name)
            sets[display]["mappings"].append(m)
    return Schema(
        sources=tuple(d for d, _ in loaded),
        mappings=tuple(
            MappingSet(d, tuple(s["concepts"]), tuple(s["endpoints"]), tuple(s["mappings"])) for d, s in sets.items()
        ),
    )


def parse_file(path: Path, *, root: Path | None = None, schema: Schema | None = None) -> Schema:
    """One mapping file on its own (its references to concepts/endpoints must be in it)."""
    return _parse([path], root, schema)


def parse_dir(root: Path, *, schema: Schema | None = None) -> Schema:
    """Every ``*.yaml`` below ``root`` in sorted path order; ``schema`` (the formats) checks references."""
    paths = sorted(p for p in root.rglob("*") if p.suffix in (".yaml", ".yml") and p.is_file())
    return _parse(paths, root, schema)


def concepts(schema: Schema) -> tuple[Concept, ...]:
    return tuple(c for s in schema.mappings for c in s.concepts)


def endpoints(schema: Schema) -> tuple[Endpoint, ...]:
    return tuple(e for s in schema.mappings for e in s.endpoints)


def all_mappings(schema: Schema) -> tuple[Mapping, ...]:
    return tuple(m for s in schema.mappings for m in s.mappings)
