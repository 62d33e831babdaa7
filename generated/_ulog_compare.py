# Copied by battgen from codegen/backends/python/runtime/_ulog_compare.py; do not edit here, edit it there.
"""Comparing a log's format with a generated class (:class:`FormatDiff`), and decoding a record
whose layout differs: fields are matched by name (through PX4's renames), values of another but
compatible type are converted with range checks (int32 -> uint8, float[10] -> float[14]), and
whatever the class cannot hold is handed back as the record's *extras*, never dropped unsaid.
Part of the ULog runtime that ``_ulog`` re-exports.
"""

from __future__ import annotations

import dataclasses
import math
import re
import types
from collections.abc import Callable, Mapping
from typing import Any

from . import _uorb
from ._ulog_format import MAX_DEPTH, TYPES, Format, Member, ULogError, format_of, layout

# Fields PX4 renamed without a change of meaning, by format: {name in older logs: name now}.
# battery_status: 'average_current_a' became 'current_average_a' (PX4 v1.12; the v1.11-era layout
# of sample_log_small.ulg still has the old name, v1.14 and later the new one). Fields PX4 removed
# (voltage_filtered_v, current_filtered_a, run_time_to_empty, serial_number...) have no successor
# with the same meaning: they stay the record's extras.
RENAMED: dict[str, dict[str, str]] = {
    "battery_status": {"average_current_a": "current_average_a"},
}

EMPTY: Mapping[str, Any] = types.MappingProxyType({})

# struct code -> (lowest, highest) value an integer C type holds
_INT_RANGES = {
    "b": (-(1 << 7), (1 << 7) - 1), "B": (0, (1 << 8) - 1), "h": (-(1 << 15), (1 << 15) - 1),
    "H": (0, (1 << 16) - 1), "i": (-(1 << 31), (1 << 31) - 1), "I": (0, (1 << 32) - 1),
    "q": (-(1 << 63), (1 << 63) - 1), "Q": (0, (1 << 64) - 1), "?": (0, 1),
}  # fmt: skip
_FLOAT32_MAX = 3.4028234663852886e38
_INDEX = re.compile(r"\[\d+\]")


@dataclasses.dataclass(frozen=True)
class Retyped:
    name: str
    schema: str  # type in the schema, as ULog spells it (float[14], uint8_t, a nested format)
    log: str  # type in the log


@dataclasses.dataclass(frozen=True)
class FormatDiff:
    """How a log's format for a topic differs from a generated class (nested fields dotted).

    ``renamed`` fields are decoded under their schema name; ``converted`` ones are decoded with a
    range check on every value (a value that does not fit stays in the record's extras); ``retyped``
    ones cannot be converted (a scalar against an array, a float into an integer) and keep their
    defaults, like ``missing`` ones; ``extra`` fields are handed out as each record's extras.
    """

    topic: str
    message: str  # the class's format name
    missing: tuple[tuple[str, str], ...]  # (field, schema type): in the schema, not in the log
    extra: tuple[tuple[str, str], ...]  # (field, log type): in the log, not in the schema
    retyped: tuple[Retyped, ...]  # in both under one name, with types that do not convert
    identical: bool  # same values at the same offsets: records decode with the class's own codec
    renamed: tuple[tuple[str, str], ...] = ()  # (name in the log, name in the schema)
    converted: tuple[Retyped, ...] = ()  # other types whose values convert (widened, range-checked)

    @property
    def matches(self) -> bool:
        """True when every field matches by name and type (the layout may still differ)."""
        return not (self.missing or self.extra or self.retyped or self.renamed or self.converted)

    def to_dict(self) -> dict[str, Any]:
        return {
            "topic": self.topic,
            "message": self.message,
            "missing": [list(x) for x in self.missing],
            "extra": [list(x) for x in self.extra],
            "retyped": [[r.name, r.schema, r.log] for r in self.retyped],
            "renamed": [list(x) for x in self.renamed],
            "converted": [[r.name, r.schema, r.log] for r in self.converted],
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
            lines.append("  only in the log (kept as extras): " + ", ".join(f"{n} {t}" for n, t in self.extra))
        if self.renamed:
            lines.append("  renamed since: " + ", ".join(f"{a} -> {b}" for a, b in self.renamed))
        if self.converted:
            lines.append(
                "  converted (range-checked): "
                + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in self.converted)
            )
        if self.retyped:
            lines.append(
                "  retyped (left at defaults): "
                + ", ".join(f"{r.name} (schema {r.schema}, log {r.log})" for r in self.retyped)
            )
        return "\n".join(lines)


def _convertible(ours: Member, theirs: Member) -> bool:
    """A log value of type ``theirs`` can be held by ``ours`` after a range check: both numbers
    (bool counting as one), no float into an integer, both scalars or both arrays."""
    if ours.kind not in ("scalar", "array") or (ours.count == 0) != (theirs.count == 0):
        return False
    mine, logged = TYPES.get(ours.ctype), TYPES.get(theirs.ctype)
    if mine is None or logged is None or "char" in (ours.ctype, theirs.ctype):
        return False
    return mine[0] in "fd" or logged[0] not in "fd"


def _compare(
    ours: Format, theirs: Format, formats: Mapping[str, Format], prefix: str, depth: int,
    out: dict[str, list[Any]],
) -> None:  # fmt: skip
    if depth > MAX_DEPTH:
        raise ULogError(f"format {theirs.name}: nested deeper than {MAX_DEPTH} levels (a cycle?)")
    renames = RENAMED.get(theirs.name, {}) if depth == 0 else {}
    ours_names = {m.name for m in ours.members}
    logged = {}
    for m in theirs.members:
        if m.is_padding:
            continue
        new = renames.get(m.name)
        if new is not None and new in ours_names and not any(x.name == new for x in theirs.members):
            out["renamed"].append((prefix + m.name, prefix + new))
            logged[new] = m
        else:
            logged[m.name] = m
    names = set()
    for m in ours.members:
        if m.is_padding:
            continue
        names.add(m.name)
        lm = logged.get(m.name)
        if lm is None:
            out["missing"].append((prefix + m.name, m.type_text))
        elif m.nested is not None and lm.ctype not in TYPES and lm.ctype in formats and m.count == lm.count:
            _compare(m.nested, formats[lm.ctype], formats, prefix + m.name + ".", depth + 1, out)
        elif (m.ctype, m.count) == (lm.ctype, lm.count):
            continue
        elif depth == 0 and _convertible(m, lm):  # PX4 never retyped inside a nested type
            out["converted"].append(Retyped(prefix + m.name, m.type_text, lm.type_text))
        else:
            out["retyped"].append(Retyped(prefix + m.name, m.type_text, lm.type_text))
    out["extra"].extend((prefix + n, m.type_text) for n, m in logged.items() if n not in names)


def compare(cls: type[Any], log_format: Format, formats: Mapping[str, Format], topic: str = "") -> FormatDiff:
    """The difference between a class's format and a log's format (nested types from ``formats``)."""
    ours = format_of(cls)
    out: dict[str, list[Any]] = {k: [] for k in ("missing", "extra", "retyped", "renamed", "converted")}
    _compare(ours, log_format, formats, "", 0, out)
    mine, theirs = layout(ours, {}), layout(log_format, formats)
    same = (mine.names, mine.codes, mine.offsets, mine.data_size) == (
        theirs.names, theirs.codes, theirs.offsets, theirs.data_size
    )  # fmt: skip
    return FormatDiff(
        topic or log_format.name,
        ours.name,
        tuple(out["missing"]),
        tuple(out["extra"]),
        tuple(out["retyped"]),
        same,
        tuple(out["renamed"]),
        tuple(out["converted"]),
    )


# A plan step: (attribute, kind, first value index, value count, nested plan, nested class)
_Step = tuple[str, str, int, int, tuple[Any, ...], Any]


def fill_plan(
    ours: Format, index: Mapping[str, int], prefix: str, path: str, skip: set[str], alias: Mapping[str, str] = EMPTY
) -> tuple[_Step, ...]:
    """How to fill a class's attributes from a log record's unpacked values (matching fields only).

    ``prefix`` spells value names as flattened (``sp[2].x``), ``path`` as the diff does (``sp.x``);
    ``alias`` maps a schema path to the log's name for it (a renamed field).
    """
    steps: list[_Step] = []
    for m in ours.members:
        if m.is_padding or path + m.name in skip:
            continue
        name = prefix + alias.get(path + m.name, m.name).rpartition(".")[2]
        if m.nested is not None:
            cls, inner = m.nested.cls, path + m.name + "."
            if m.count:
                subs = tuple(fill_plan(m.nested, index, f"{name}[{i}].", inner, skip, alias) for i in range(m.count))
                steps.append((m.attr, "nested_array", 0, m.count, subs, cls))
            else:
                sub = fill_plan(m.nested, index, name + ".", inner, skip, alias)
                steps.append((m.attr, "nested", 0, 0, (sub,), cls))
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


def _fits(code: str) -> Callable[[Any], bool]:
    """Whether a value fits the C type of struct code ``code`` (NaN and infinities fit a float)."""
    if code == "f":
        return lambda x: not math.isfinite(x) or abs(x) <= _FLOAT32_MAX
    if code == "d":
        return lambda x: True
    lo, hi = _INT_RANGES[code]
    return lambda x: lo <= x <= hi


# A conversion step: (attribute, value indexes in the log record, the log's flattened names,
# schema count (0: scalar), the value's check, the value's cast)
_Convert = tuple[str, tuple[int, ...], tuple[str, ...], int, Callable[[Any], bool], Callable[[Any], Any]]


def convert_plan(
    ours: Format, converted: tuple[Retyped, ...], renamed: Mapping[str, str], names: tuple[str, ...]
) -> tuple[_Convert, ...]:
    """How to convert the top-level fields of another but compatible type (nested ones stay
    unconverted: PX4 never retyped inside a nested battery type)."""
    index = {n: i for i, n in enumerate(names)}
    members = {m.name: m for m in ours.members}
    steps: list[_Convert] = []
    for r in converted:
        m = members.get(r.name)
        if m is None:
            continue
        log_name = renamed.get(r.name, r.name)
        count = int(r.log.partition("[")[2].rstrip("]") or 0)
        flat = tuple(f"{log_name}[{i}]" for i in range(count)) if count else (log_name,)
        at = tuple(index[n] for n in flat if n in index)
        code = TYPES[m.ctype][0]
        cast: Callable[[Any], Any] = float if code in "fd" else bool if code == "?" else int
        steps.append((m.attr, at, flat, m.count, _fits(code), cast))
    return tuple(steps)


def convert(obj: Any, plan: tuple[_Convert, ...], v: tuple[Any, ...], extras: dict[str, Any]) -> list[str]:
    """Apply a convert plan to ``obj``; values that do not fit, and array elements beyond the
    class's length, go into ``extras`` under the log's name. Returns the names that did not fit."""
    unfit: list[str] = []
    for attr, at, flat, count, fits, cast in plan:
        if not count:
            x = v[at[0]]
            if fits(x):
                setattr(obj, attr, cast(x))
            else:
                extras[flat[0]] = x
                unfit.append(flat[0])
            continue
        values = list(getattr(obj, attr))
        for k, (i, name) in enumerate(zip(at, flat, strict=True)):
            x = v[i]
            if k < count and fits(x):
                values[k] = cast(x)
            else:
                extras[name] = x
                if k < count:
                    unfit.append(name)
        setattr(obj, attr, values)
    return unfit


def extra_indexes(extra: tuple[tuple[str, str], ...], names: tuple[str, ...]) -> tuple[tuple[int, str], ...]:
    """(value index, flattened name) of every value of the log-only fields (``many[1].x`` is a
    value of the field the diff calls ``many.x``)."""
    paths = {n for n, _ in extra}
    out = []
    for i, n in enumerate(names):
        path = _INDEX.sub("", n)
        while path not in paths and "." in path:
            path = path.rpartition(".")[0]
        if path in paths:
            out.append((i, n))
    return tuple(out)
