"""Cross-field rules and the Schema that holds everything one load produced."""

from __future__ import annotations

from dataclasses import dataclass, field

from .basics import Location, SchemaWarning
from .expr import RuleExpressions
from .fields import EnumDef, Field
from .fieldtypes import ArrayType, CompositeType
from .mappings import MappingSet
from .messages import Message


@dataclass(frozen=True)
class CrossFieldRule:
    """A rule relating fields of a message that its schema cannot state.

    ``exprs`` holds the expressions parsed (:mod:`codegen.ir.expr`), with loop variables resolved;
    the frontend has checked that the other names bind to each message in ``messages`` (see
    :func:`codegen.ir.rules.bind`). The text fields keep the expressions as written: the JSON form
    shows them, and a violation quotes the ``assert``. ``lines`` gives the source line of each key
    (``assert``, ``where``, ``for``, ``for[i]``, ``path``, ``message``).
    """

    id: str
    messages: tuple[str, ...]
    severity: str  # "error" or "warning" (advice)
    check: str  # the ``assert`` expression
    location: Location
    exprs: RuleExpressions = field(metadata={"json_form": False})  # the text fields, parsed
    doc: str = ""
    where: str | None = None
    loops: tuple[str, ...] = ()  # ``for`` clauses, "name in expression"
    path: str | None = None
    message: str = ""
    lines: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True)
class Schema:
    """Everything parsed from a set of sources: messages, and enums shared across messages."""

    messages: tuple[Message, ...] = ()
    enums: tuple[EnumDef, ...] = ()
    sources: tuple[str, ...] = field(default=())
    mappings: tuple[MappingSet, ...] = ()
    rules: tuple[CrossFieldRule, ...] = ()
    # what the frontends accepted with a warning; printed on stderr, not part of the JSON form
    warnings: tuple[SchemaWarning, ...] = field(default=(), metadata={"json_form": False}, compare=False)

    def message(self, qualified_name: str) -> Message:
        for m in self.messages:
            if m.qualified_name == qualified_name:
                return m
        raise KeyError(qualified_name)

    def field_at(self, qualified_name: str, path: str) -> Field:
        """The field a mapping's dotted path names: ``voltage``, or through composite fields and array
        elements ``power.current.ampere`` / ``temperature_min_max.1.kelvin`` (Cyphal's nested types)."""
        return self._walk(qualified_name, path)[1]

    def owner_at(self, qualified_name: str, path: str) -> Message:
        """The message that declares the field a dotted path names: for ``error.value`` of a UDRAL Status, the
        Error type (whose constants name the field's values); the message itself for a path that names none of
        its fields (a rule on the whole message)."""
        try:
            return self._walk(qualified_name, path)[0]
        except KeyError:
            return self.message(qualified_name)

    def _walk(self, qualified_name: str, path: str) -> tuple[Message, Field]:
        msg = self.message(qualified_name)
        steps = path.split(".")
        f = msg.field(steps[0])
        t = f.type
        for step in steps[1:]:
            if step.isdigit() and isinstance(t, ArrayType) and (t.capacity is None or int(step) < t.capacity):
                t = t.element
                continue
            if not isinstance(t, CompositeType):
                raise KeyError(path)
            msg = self.message(t.name)
            f = msg.field(step)
            t = f.type
        if len(steps) > 1 and steps[-1].isdigit():
            raise KeyError(path)  # a path ends at a field, not at an element
        return msg, f

    def enum(self, name: str) -> EnumDef:
        for e in self.enums:
            if e.name == name:
                return e
        for m in self.messages:
            for e in m.enums:
                if e.name == name:
                    return e
        raise KeyError(name)

    def merged(self, other: Schema) -> Schema:
        return Schema(
            messages=self.messages + other.messages,
            enums=self.enums + other.enums,
            sources=self.sources + other.sources,
            mappings=self.mappings + other.mappings,
            rules=self.rules + other.rules,
            warnings=self.warnings + other.warnings,
        )
