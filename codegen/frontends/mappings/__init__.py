"""Frontend for converter mappings (``schemas/mappings/*.yaml``): concepts, endpoints, mappings.

Each file is safe-loaded with line numbers, checked against the mappings JSON Schema
(:mod:`.json_schema`), and turned into IR (:class:`~codegen.ir.MappingSet`); each rule's
parameters become its typed op (:mod:`codegen.ir.ops`, read by :mod:`.op_params`). Given the
formats' Schema, every reference (message, field, constant, concept, unit) is checked
(:mod:`.resolver`), so a typo is a SchemaError naming the file and line rather than a broken
converter.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

from ...errors import SchemaError
from ...ir import CONCEPTS_ENDPOINT, Concept, Direction, Endpoint, Location, Mapping, MappingSet, Rule, Schema, units
from ...ir.ops import OPS, Arity
from ...text.files import display_path
from ...text.limits import read_schema_text
from ...text.yaml_lines import YMap, line_at, load
from .fast_check import mapping_file_check
from .json_schema import mappings_json_schema
from .op_params import build_op
from .resolver import Resolver

__all__ = ["MAPPED_FORMATS", "all_mappings", "concepts", "endpoints", "mappings_json_schema", "parse_dir", "parse_file"]


# the formats an endpoint's messages may come from (the pattern of mappings.schema.json's endpoint
# messages): a catalog of the mappings needs these folders and no other
MAPPED_FORMATS = ("uorb", "dronecan", "devicetree", "mavlink", "cyphal")

# the mapping files shipped with battgen (the checkout's schemas/mappings/, as codegen.apps.schemas.package
# finds it): they take the compiled check (.fast_check), every other file jsonschema itself
_BUNDLED_DIR = Path(__file__).resolve().parents[3] / "schemas" / "mappings"


def _is_bundled(path: Path) -> bool:
    try:
        return _BUNDLED_DIR in path.resolve().parents
    except OSError:
        return False


@cache
def _validator() -> Any:
    """The jsonschema validator, built once per process (its schema and $ref registry are the same for every file)."""
    import jsonschema  # here, not at the top: a command on the bundled schemas never needs it

    return jsonschema.Draft202012Validator(mappings_json_schema())


def _validate(doc: Any, display: str) -> None:
    import jsonschema

    validator = _validator()
    errors = sorted(validator.iter_errors(doc), key=lambda e: (len(e.absolute_path), list(map(str, e.absolute_path))))
    if errors:
        err = errors[0]
        best = jsonschema.exceptions.best_match(errors) or err
        path = list(best.absolute_path)
        where = "/".join(str(p) for p in path) or "the top level"
        raise SchemaError(display, line_at(doc, path), f"expected a valid mapping file at {where}: {best.message}")


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


def _endpoints(doc: YMap, display: str, resolver: Resolver) -> list[Endpoint]:
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


def _refs(body: YMap, key: str, arity: Arity, op: str, display: str) -> list[str]:
    """The references written under ``key`` (one, or a list), as many as the op takes."""
    value = body.get(key, [])
    refs = [value] if isinstance(value, str) else list(value)
    least, most = arity
    if not least <= len(refs) <= (len(refs) if most is None else most):
        wanted = f"{least}" if least == most else f"at least {least}" if most is None else f"{least} to {most}"
        raise SchemaError(
            display, body.line_of(key), f"expected {wanted} reference(s) in {key!r} for op {op!r}, got {len(refs)}"
        )
    return refs


def _rule(body: YMap, source: Endpoint | None, target: Endpoint | None, display: str, resolver: Resolver) -> Rule:
    cls = OPS[body["op"]]
    targets = tuple(
        resolver.ref(r, target, display, body.line_of("to")) for r in _refs(body, "to", cls.TARGETS, cls.NAME, display)
    )
    sources = tuple(
        resolver.ref(r, source, display, body.line_of("from"))
        for r in _refs(body, "from", cls.SOURCES, cls.NAME, display)
    )
    only = Direction(body["only"]) if "only" in body else None
    doc = body.get("doc", "").strip()
    rule = Rule(build_op(cls, body, display), targets, sources, doc, Location(display, body.line), only)
    resolver.check_rule(rule, display, body.line)
    return rule


def _mappings(doc: YMap, display: str, resolver: Resolver) -> list[Mapping]:
    out = []
    for body in doc.get("mappings", []):
        source = resolver.endpoint(body["source"], display, body.line_of("source"))
        target = resolver.endpoint(body["target"], display, body.line_of("target"))
        out.append(
            Mapping(
                name=body["name"],
                source=body["source"],
                target=body["target"],
                policy=body.get("policy", "strict"),
                rules=tuple(_rule(r, source, target, display, resolver) for r in body["rules"]),
                reversible=bool(body.get("reversible", False)),
                doc=body.get("doc", "").strip(),
                location=Location(display, body.line),
            )
        )
    return out


def _load(path: Path, root: Path | None) -> tuple[str, YMap]:
    display = display_path(path, root)
    doc = load(read_schema_text(path, display), display)
    if not isinstance(doc, YMap):
        raise SchemaError(display, getattr(doc, "line", 1) or 1, "expected a mapping file (a YAML mapping)")
    if not (_is_bundled(path) and mapping_file_check()(doc)):
        _validate(doc, display)  # a user's file, or a bundled one the fast check refused: jsonschema's error
    return display, doc


def _parse(paths: list[Path], root: Path | None, schema: Schema | None) -> Schema:
    resolver = Resolver(schema)
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
