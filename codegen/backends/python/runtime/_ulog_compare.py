"""Comparing a log's format with a generated class (:class:`FormatDiff`), and filling an instance
with the fields that match by name and type when a record's layout differs. Part of the ULog
runtime that ``_ulog`` re-exports.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from . import _uorb
from ._ulog_format import MAX_DEPTH, TYPES, Format, ULogError, format_of, layout


@dataclasses.dataclass(frozen=True)
class Retyped:
    name: str
    schema: str  # type in the schema, as ULog spells it (float[14], uint8_t, a nested format)
    log: str  # type in the log


@dataclasses.dataclass(frozen=True)
class FormatDiff:
    """How a log's format for a topic differs from a generated class (nested fields dotted)."""

    topic: str
    message: str  # the class's format name
    missing: tuple[tuple[str, str], ...]  # (field, schema type): in the schema, not in the log
    extra: tuple[tuple[str, str], ...]  # (field, log type): in the log, not in the schema
    retyped: tuple[Retyped, ...]  # in both under one name, with different types
    identical: bool  # same values at the same offsets: records decode with the class's own codec

    @property
    def matches(self) -> bool:
        """True when every field matches by name and type (the layout may still differ)."""
        return not (self.missing or self.extra or self.retyped)

    def to_dict(self) -> dict[str, Any]:
        return {
            "topic": self.topic,
            "message": self.message,
            "missing": [list(x) for x in self.missing],
            "extra": [list(x) for x in self.extra],
            "retyped": [[r.name, r.schema, r.log] for r in self.retyped],
            "identical": self.identical,
        }

    def __str__(self) -> str:
        if self.identical:
            return f"{self.topic}: the log's format is the schema's ({self.message})"
        head = f"{self.topic}: the log's format differs from the schema ({self.message})"
        lines = [head if not self.matches else head + ": same fields, other layout"]
        if self.missing:
            lines.append("  missing from the log (left at defaults): " + ", ".join(f"{n} {t}" for n, t in self.missing))
        if self.extra:
            lines.append("  only in the log (not decoded): " + ", ".join(f"{n} {t}" for n, t in self.extra))
        if self.retyped:
            lines.append(
                "  retyped (left at defaults): "
                + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in self.retyped)
            )
        return "\n".join(lines)


def _compare(
    ours: Format, theirs: Format, formats: Mapping[str, Format], prefix: str, depth: int,
    missing: list[tuple[str, str]], extra: list[tuple[str, str]], retyped: list[Retyped],
) -> None:  # fmt: skip
    if depth > MAX_DEPTH:
        raise ULogError(f"format {theirs.name}: nested deeper than {MAX_DEPTH} levels (a cycle?)")
    logged = {m.name: m for m in theirs.members if not m.is_padding}
    names = set()
    for m in ours.members:
        if m.is_padding:
            continue
        names.add(m.name)
        lm = logged.get(m.name)
        if lm is None:
            missing.append((prefix + m.name, m.type_text))
        elif m.nested is not None and lm.ctype not in TYPES and lm.ctype in formats and m.count == lm.count:
            _compare(m.nested, formats[lm.ctype], formats, prefix + m.name + ".", depth + 1, missing, extra, retyped)
        elif (m.ctype, m.count) != (lm.ctype, lm.count):
            retyped.append(Retyped(prefix + m.name, m.type_text, lm.type_text))
    extra.extend((prefix + m.name, m.type_text) for m in theirs.members if not m.is_padding and m.name not in names)


def compare(cls: type[Any], log_format: Format, formats: Mapping[str, Format], topic: str = "") -> FormatDiff:
    """The difference between a class's format and a log's format (nested types from ``formats``)."""
    ours = format_of(cls)
    missing: list[tuple[str, str]] = []
    extra: list[tuple[str, str]] = []
    retyped: list[Retyped] = []
    _compare(ours, log_format, formats, "", 0, missing, extra, retyped)
    mine, theirs = layout(ours, {}), layout(log_format, formats)
    same = (mine.names, mine.codes, mine.offsets, mine.data_size) == (
        theirs.names, theirs.codes, theirs.offsets, theirs.data_size
    )  # fmt: skip
    return FormatDiff(topic or log_format.name, ours.name, tuple(missing), tuple(extra), tuple(retyped), same)


# A plan step: (attribute, kind, first value index, value count, nested plan, nested class)
_Step = tuple[str, str, int, int, tuple[Any, ...], Any]


def fill_plan(ours: Format, index: Mapping[str, int], prefix: str, path: str, skip: set[str]) -> tuple[_Step, ...]:
    """How to fill a class's attributes from a log record's unpacked values (matching fields only).

    ``prefix`` spells value names as flattened (``sp[2].x``), ``path`` as the diff does (``sp.x``).
    """
    steps: list[_Step] = []
    for m in ours.members:
        name = prefix + m.name
        if m.is_padding or path + m.name in skip:
            continue
        if m.nested is not None:
            cls, inner = m.nested.cls, path + m.name + "."
            if m.count:
                subs = tuple(fill_plan(m.nested, index, f"{name}[{i}].", inner, skip) for i in range(m.count))
                steps.append((m.attr, "nested_array", 0, m.count, subs, cls))
            else:
                steps.append((m.attr, "nested", 0, 0, (fill_plan(m.nested, index, name + ".", inner, skip),), cls))
            continue
        first = index.get(f"{name}[0]" if m.count and m.ctype != "char" else name)
        if first is None:
            continue
        steps.append((m.attr, m.kind, first, m.count, (), None))
    return tuple(steps)


def fill(obj: Any, plan: tuple[_Step, ...], v: tuple[Any, ...]) -> Any:
    for attr, kind, i, n, subs, cls in plan:
        if kind == "scalar":
            value = v[i]
        elif kind == "array":
            value = list(v[i : i + n])
        elif kind == "bytes":
            value = bytes(v[i : i + n])
        elif kind == "string":
            value = _uorb.cstr_decode(v[i])
        elif kind == "char":
            value = _uorb.char_decode(v[i])
        elif kind == "nested":
            value = fill(cls(), subs[0], v)
        else:  # nested_array
            value = [fill(cls(), sub, v) for sub in subs]
        setattr(obj, attr, value)
    return obj
