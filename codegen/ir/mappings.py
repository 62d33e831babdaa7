"""Concepts and mappings (schemas/mappings/*.yaml): what converters between formats are made of."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from .basics import Location, Unit
from .ops import MappingOp


@dataclass(frozen=True)
class Concept:
    """A shared battery quantity (pack voltage, state of charge...), in SI units.

    ``kind`` is ``number``, ``integer``, ``bool``, ``text``, ``list`` (of numbers), ``choice``
    (one of ``choices``) or ``flags`` (a set drawn from ``choices``); ``unit`` None when unitless.
    """

    name: str
    kind: str
    unit: Unit | None = None
    doc: str = ""
    choices: tuple[str, ...] = ()
    location: Location | None = None


@dataclass(frozen=True)
class FieldRef:
    """A field of a message (qualified name), or a concept (``message`` is ``"concepts"``)."""

    message: str
    field: str


class Direction(str, enum.Enum):
    """A direction of a reversible mapping: source -> target (forward) or back."""

    FORWARD = "forward"
    BACKWARD = "backward"


@dataclass(frozen=True)
class Rule:
    """One step of a mapping: ``op`` (a typed op of :mod:`codegen.ir.ops`, holding its parameters)
    computes ``targets`` from ``sources``; ``only`` limits it to one direction of a reversible mapping."""

    op: MappingOp
    targets: tuple[FieldRef, ...]
    sources: tuple[FieldRef, ...]
    doc: str = ""
    location: Location | None = None
    only: Direction | None = None


@dataclass(frozen=True)
class Endpoint:
    """What a converter reads or writes: one or more messages (the first required, the rest
    optional companions such as DroneCAN's BatteryInfoAux), each known by a short alias."""

    name: str
    messages: tuple[str, ...]
    aliases: tuple[str, ...]
    doc: str = ""
    location: Location | None = None


CONCEPTS_ENDPOINT = "concepts"  # the shared battery state every format maps to and from


@dataclass(frozen=True)
class Mapping:
    """How to turn the ``source`` endpoint into the ``target`` endpoint under ``policy``.

    ``reversible`` mappings are also generated target -> source; ``policy`` is ``strict``,
    ``px4``, ``ardupilot`` (the code of that firmware) or ``any``.
    """

    name: str
    source: str
    target: str
    policy: str
    rules: tuple[Rule, ...]
    reversible: bool = False
    doc: str = ""
    location: Location | None = None


@dataclass(frozen=True)
class MappingSet:
    """Everything one mapping file declares: concepts, endpoints and/or mappings."""

    file: str
    concepts: tuple[Concept, ...] = ()
    endpoints: tuple[Endpoint, ...] = ()
    mappings: tuple[Mapping, ...] = ()
