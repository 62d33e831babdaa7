"""Name resolution for mapping files: concepts, endpoints, messages, fields and constants.

Given the formats' Schema, every reference a rule makes is checked, so a typo is a SchemaError
naming the file and line rather than a broken converter. Without one (a mapping file read on
its own), only concepts and endpoints are checked.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

from ...errors import SchemaError
from ...ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Concept,
    Endpoint,
    FieldRef,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Rule,
    Schema,
    units,
)
from ...ir.basics import Unit
from ...ir.mapping_values import ConstantRef
from ...ir.ops import Cells, PX4Conversion, PX4Convert, Scale


class Resolver:
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
        if msg is not None and self.schema is not None:
            try:
                self.schema.field_at(qualified, field)
            except KeyError:
                raise SchemaError(display, line, f"expected a field of {qualified}, got {field!r}") from None
        return FieldRef(qualified, field)

    def check_rule(self, rule: Rule, display: str, line: int) -> None:
        """What only the formats can tell: named constants exist, ``cells`` relates arrays."""
        if self.schema is None:
            return
        names: set[str] = set()
        for ref in rule.targets + rule.sources:
            if ref.message != CONCEPTS_ENDPOINT:
                names.update(c.name for c in self.schema.message(ref.message).constants)
                names.update(c.name for c in self.schema.owner_at(ref.message, ref.field).constants)
        for e in self.schema.enums:
            names.update(x.name for x in e.entries)
        for const in _constants(rule.op):
            if const.name not in names:
                raise SchemaError(display, line, f"expected a constant of the messages used, got {const.name!r}")
        if isinstance(rule.op, Cells):
            for ref in rule.targets + rule.sources:
                if ref.message != CONCEPTS_ENDPOINT and not isinstance(
                    self.schema.field_at(ref.message, ref.field).type, ArrayType
                ):
                    raise SchemaError(display, line, f"expected an array field for op 'cells', got {ref.field!r}")
        self._check_units(rule, display, line)
        self._check_written_marker(rule, display, line)

    def _check_written_marker(self, rule: Rule, display: str, line: int) -> None:
        """The first ``unknown`` marker is what a converter writes for unknown: an integer field needs
        an integer one (NaN and fractions are for float fields)."""
        markers = getattr(rule.op, "unknown", None)
        if not isinstance(markers, tuple) or not markers or self.schema is None:
            return
        first = markers[0]
        if not isinstance(first, float) or first.is_integer():
            return
        for ref in rule.sources + rule.targets:
            if ref.message == CONCEPTS_ENDPOINT or not ref.field:
                continue
            t = self.schema.field_at(ref.message, ref.field).type
            while isinstance(t, ArrayType):
                t = t.element
            if isinstance(t, PrimitiveType) and t.kind is not PrimitiveKind.FLOAT:
                raise SchemaError(
                    display,
                    line,
                    f"expected an integer as the first 'unknown' marker (written for unknown): {ref.field} holds "
                    f"{t.kind.value}{t.bits} values, got {first}",
                )

    def _unit(self, ref: FieldRef) -> Unit | None:
        if ref.message == CONCEPTS_ENDPOINT:
            concept = self.concepts.get(ref.field)
            return concept.unit if concept is not None else None
        if self.schema is None or not ref.field:
            return None
        return self.schema.field_at(ref.message, ref.field).unit

    def _check_units(self, rule: Rule, display: str, line: int) -> None:
        """Ops that convert between units need units of one quantity (volts to millivolts, not to amperes)."""
        op = rule.op
        if isinstance(op, Scale | Cells):
            pairs = [(self._unit(s), self._unit(t)) for s in rule.sources for t in rule.targets]
        elif isinstance(op, PX4Convert) and op.convert is PX4Conversion.UNITS:
            su = units.lookup(op.source_unit) if op.source_unit else self._unit(rule.sources[0])
            tu = units.lookup(op.target_unit) if op.target_unit else self._unit(rule.targets[0])
            if su is None or tu is None:
                raise SchemaError(display, line, "expected units on both sides of px4_convert with convert: units")
            pairs = [(su, tu)]
        else:
            return
        for su, tu in pairs:
            if su is not None and tu is not None and su.quantity != tu.quantity:
                raise SchemaError(
                    display,
                    line,
                    f"expected units of one quantity for op {op.NAME!r}, got {su.symbol} ({su.quantity}) "
                    f"and {tu.symbol} ({tu.quantity})",
                )


def _constants(value: object) -> Iterator[ConstantRef]:
    """Every constant an op's parameters name, in order."""
    if isinstance(value, ConstantRef):
        yield value
    elif isinstance(value, tuple):
        for item in value:
            yield from _constants(item)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            yield from _constants(getattr(value, f.name))
