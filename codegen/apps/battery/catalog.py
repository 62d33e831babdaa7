"""What the fleet table is made of, read from the IR: the shared concepts and, per source message,
the forward rules of its mapping to them (``schemas/mappings/``).

The table's concept columns, their units and quantities, and which field of which message feeds
each one all come from here, so the export has no unit, sentinel or field name of its own.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

from ...errors import BattgenError
from ...ir import CONCEPTS_ENDPOINT, Concept, Direction, Endpoint, Message, Rule, Schema
from ..schemas.package import bundled_schemas, load_schemas

# codegen.frontends.mappings.MAPPED_FORMATS and codegen.frontends.loader.MAPPINGS_DIR, written here as importing
# either module imports the frontends, which a fresh cache spares (tests/apps/test_ir_cache.py checks they agree)
_MAPPED_FORMATS = ("uorb", "dronecan", "devicetree", "mavlink", "cyphal")
_MAPPINGS_DIR = "mappings"

# endpoints whose messages are battery records in logs (devicetree nodes are static facts)
RECORD_ENDPOINTS = ("uorb", "uorb_v0", "mavlink", "dronecan", "cbat", "mavlink_sys_status", "udral")


@dataclass(frozen=True)
class SourceMapping:
    """How one source message becomes the concepts: its endpoint's forward rules that read it alone
    (a companion message such as DroneCAN's BatteryInfoAux is not in a log's records)."""

    endpoint: str
    message: Message
    rules: tuple[Rule, ...]

    @functools.cached_property
    def fields(self) -> frozenset[str]:
        """Every field of the message a rule reads (sources, and a cells rule's count field)."""
        out = {s.field for rule in self.rules for s in rule.sources if s.message == self.message.qualified_name}
        out |= {f for rule in self.rules if (f := getattr(rule.op, "count_field", None)) is not None}
        return frozenset(out)

    def sources_of(self, concept: str) -> tuple[str, ...]:
        """The fields of the message a concept is read from."""
        out: list[str] = []
        for rule in self.rules:
            if any(t.field == concept for t in rule.targets):
                out.extend(s.field for s in rule.sources if s.field not in out)
        return tuple(out)


@dataclass(frozen=True)
class Catalog:
    """The concepts (in the order concepts.yaml lists them) and the record messages' mappings."""

    schema: Schema
    concepts: tuple[Concept, ...]
    sources: dict[str, SourceMapping]  # by qualified message name
    # an endpoint's other messages (DroneCAN's BatteryInfoAux), with the rules that read them alone
    companions: dict[str, SourceMapping]
    # by record message: the rules reading several of its companions together (UDRAL's SoC from Status's charge
    # over Parameters' design capacity), as a mapping of the first companion they read
    joint: dict[str, SourceMapping] = dataclasses.field(default_factory=dict)

    def concept(self, name: str) -> Concept:
        for c in self.concepts:
            if c.name == name:
                return c
        raise KeyError(name)

    def source(self, qualified: str) -> SourceMapping:
        found = self.sources.get(qualified)
        if found is None:
            known = ", ".join(sorted(self.sources))
            raise BattgenError(f"{qualified} is not a battery record message (expected one of {known})")
        return found


def build_catalog(schema: Schema) -> Catalog:
    """The catalog of an IR that holds the concepts and the record formats' mappings."""
    concepts: list[Concept] = []
    endpoints: dict[str, Endpoint] = {}
    for mset in schema.mappings:
        concepts.extend(mset.concepts)
        endpoints.update({e.name: e for e in mset.endpoints})
    sources: dict[str, SourceMapping] = {}
    companions: dict[str, SourceMapping] = {}
    joint: dict[str, SourceMapping] = {}
    for mset in schema.mappings:
        for mapping in mset.mappings:
            if mapping.target != CONCEPTS_ENDPOINT or mapping.source not in RECORD_ENDPOINTS:
                continue
            endpoint = endpoints.get(mapping.source)
            if endpoint is None:
                continue
            first = endpoint.messages[0]
            rules = tuple(
                r
                for r in mapping.rules
                if r.only in (None, Direction.FORWARD) and all(s.message == first for s in r.sources)
            )
            sources[first] = SourceMapping(mapping.source, schema.message(first), rules)
            for other in endpoint.messages[1:]:
                alone = tuple(
                    r
                    for r in mapping.rules
                    if r.only in (None, Direction.FORWARD) and r.sources and all(s.message == other for s in r.sources)
                )
                if alone:
                    companions[other] = SourceMapping(mapping.source, schema.message(other), alone)
            together = tuple(
                r
                for r in mapping.rules
                if r.only in (None, Direction.FORWARD)
                and len({s.message for s in r.sources}) > 1
                and all(s.message in endpoint.messages[1:] for s in r.sources)
            )
            if together:
                joint[first] = SourceMapping(mapping.source, schema.message(together[0].sources[0].message), together)
    if not concepts or not sources:
        raise BattgenError("the schemas hold no battery concepts or mappings to them (schemas/mappings/)")
    return Catalog(schema, tuple(concepts), sources, companions, joint)


@functools.cache
def bundled_catalog(schema_dir: Path | None = None) -> Catalog:
    """The catalog of the bundled schemas (read once per process).

    Of the bundled folder only what the mappings can name is read (the formats their endpoints'
    messages come from, and the mappings): every command starts here, and the Cyphal types (pydsdl),
    the parameter metadata and the validator rules are no part of a battery reading. A folder
    given is read whole, so every error in it is still reported. The bundled folder's IR comes from the cache
    (:func:`~codegen.apps.schemas.package.load_schemas`): no frontend is imported when it is fresh."""
    if schema_dir is None:
        return build_catalog(load_schemas(bundled_schemas(), only=(*_MAPPED_FORMATS, _MAPPINGS_DIR)))
    from ...frontends.loader import load

    return build_catalog(load([schema_dir]))
