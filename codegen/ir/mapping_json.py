"""Mapping ops in the IR's JSON form: each op's parameters as its mapping file wrote them.

``battgen ir`` writes a rule as ``op`` (the op's name), ``targets``, ``sources`` and ``params``:
key/value pairs in the op's field order, left-out parameters omitted, mappings as lists of
pairs, named constants by name (see :func:`rule_json`).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

from .mapping_values import ConstantRef, Entry
from .mappings import Rule
from .ops import MappingOp

WrittenValue = int | float | bool | str | None | tuple["WrittenValue | WrittenArgument", ...]


@dataclass(frozen=True)
class WrittenArgument:
    """One parameter as a mapping file writes it: a key and its value, mappings as tuples of these."""

    name: str
    value: WrittenValue


def _written(value: object) -> WrittenValue:
    if isinstance(value, ConstantRef):
        return value.name
    if isinstance(value, enum.Enum):
        return _written(value.value)
    if isinstance(value, Entry):
        return _written_entry(value)
    if isinstance(value, tuple):
        return tuple(_entry_argument(v) if isinstance(v, Entry) else _written(v) for v in value)
    if value is None or isinstance(value, int | float | str):
        return value
    raise TypeError(f"not a mapping op parameter: {type(value).__name__}")


def _entry_argument(entry: Entry) -> WrittenArgument:
    key = fields(entry)[0]
    return WrittenArgument(str(_written(getattr(entry, key.name))), _written_entry(entry))


def _written_entry(entry: Entry) -> WrittenValue:
    rest = fields(entry)[1:]
    if len(rest) == 1:
        return _written(getattr(entry, rest[0].name))
    return tuple(
        WrittenArgument(f.name, _written(getattr(entry, f.name))) for f in rest if _given(getattr(entry, f.name))
    )


def _given(value: object) -> bool:
    """Whether a parameter was written: left-out ones are None, () or False."""
    return value is not None and value is not False and value != ()


def written_arguments(op: MappingOp) -> tuple[WrittenArgument, ...]:
    """The op's parameters as its mapping file wrote them, in field order, left-out ones omitted."""
    return tuple(
        WrittenArgument(f.name, _written(getattr(op, f.name))) for f in fields(op) if _given(getattr(op, f.name))
    )


def rule_json(rule: Rule, jsonable: Callable[[object], Any]) -> dict[str, Any]:
    """A rule's JSON form; ``jsonable`` turns the IR values in it into JSON data; ``only`` is the last param."""
    only = [{"name": "only", "value": rule.only.value}] if rule.only is not None else []
    return {
        "op": rule.op.NAME,
        "targets": jsonable(rule.targets),
        "sources": jsonable(rule.sources),
        "params": jsonable(written_arguments(rule.op)) + only,
        "doc": rule.doc,
        "location": jsonable(rule.location),
    }
