"""Run-time support of the generated validators: violations, the error carrying them, and the
careful diagnosis of a value the generated fast path flagged.

Each generated ``validate()`` checks every field with specialised straight-line code; only a field
that fails (or holds a value of the wrong Python type) is handed to :func:`diag`, which works out
exactly what is wrong from the field's spec and words it for a firmware engineer. Standard library
only, so the generated package can be vendored as it is.

Rule ids: ``type`` (wrong kind of value), ``type-bounds`` (beyond the bit width or float format),
``nan``, ``range``, ``enum``, ``bitmask``, ``length``, ``required``, ``pattern``, ``union`` (a DroneCAN
union whose ``union_field`` names no branch, or a branch that holds no value),
``cross-field:<rule id>`` (rules from schemas/rules/).
"""

from __future__ import annotations

import dataclasses
import enum
import math
import re
from collections.abc import Mapping, Sequence

from ._meta import brief, clip

__all__ = ["Severity", "ValidationError", "Violation"]


class Severity(enum.StrEnum):
    """Errors make an instance invalid; warnings are advice and never do."""

    ERROR = "error"
    WARNING = "warning"


@dataclasses.dataclass(frozen=True, slots=True)
class Violation:
    """One broken rule: where (``voltage_cell_v[3]``, ``timestamp.usec``), which rule, the value
    found, the limit it broke (a bound, the allowed set, or a rule's text) and a sentence."""

    path: str
    rule: str
    value: object
    limit: object
    message: str
    severity: str = Severity.ERROR

    def __str__(self) -> str:
        return self.message if self.severity == Severity.ERROR else "warning: " + self.message


class ValidationError(ValueError):
    """Raised by ``check()`` when there is at least one error; carries every violation found."""

    def __init__(self, violations: Sequence[Violation], name: str = "") -> None:
        self.violations: tuple[Violation, ...] = tuple(violations)
        errors = self.errors
        head = f"{name}: " if name else ""
        count = f"{len(errors)} violation" + ("" if len(errors) == 1 else "s")
        super().__init__(head + count + ": " + "; ".join(v.message for v in errors))

    @property
    def errors(self) -> tuple[Violation, ...]:
        return tuple(v for v in self.violations if v.severity == Severity.ERROR)

    @property
    def warnings(self) -> tuple[Violation, ...]:
        return tuple(v for v in self.violations if v.severity != Severity.ERROR)


# What the fast path may raise on a value of the wrong type; the field is then diagnosed carefully.
SLOW: tuple[type[Exception], ...] = (
    TypeError,
    AttributeError,
    ValueError,
    OverflowError,
    IndexError,
    KeyError,
    ZeroDivisionError,
)


# ---------------------------------------------------------------------------------------------
# Field specs: what the generated modules declare once per field, read only when diagnosing.


@dataclasses.dataclass(frozen=True, slots=True)
class Number:
    """A primitive value: bool, uintN, intN, floatN or char, with its schema facts."""

    type: str  # as the schema spells it: uint7, float16
    kind: str  # bool, uint, int, float, char
    low: float  # representable range
    high: float
    unit: str = ""
    minimum: float | None = None  # the schema's range
    maximum: float | None = None
    exclusive_minimum: bool = False
    exclusive_maximum: bool = False
    sentinel: float | None = None  # the "unknown" value
    sentinel_text: str = ""
    values: Mapping[int, str] | None = None  # value enum: allowed value -> member name
    mask: int | None = None  # bitmask: the bits that may be set
    bits: Mapping[int, str] | None = None  # bitmask: bit value -> member name (reserved ones too)
    label: str = ""  # what the array position holds (a column's doc), named in messages


@dataclasses.dataclass(frozen=True, slots=True)
class Text:
    capacity: int | None = None  # in UTF-8 bytes
    choices: tuple[str, ...] = ()
    const: str | None = None
    label: str = ""


@dataclasses.dataclass(frozen=True, slots=True)
class Array:
    element: Spec
    capacity: int | None
    fixed: bool
    min_length: int = 0
    byte: bool = False  # held as bytes
    columns: tuple[Spec | None, ...] = ()  # element i's own spec (None: the element's)
    unknown_first: float | None = None  # MAVLink [X:]: element 0 holding X makes the whole array unknown


@dataclasses.dataclass(frozen=True, slots=True)
class Nested:
    type: str  # qualified name of the message


@dataclasses.dataclass(frozen=True, slots=True)
class Optional:
    """A devicetree property: None when absent."""

    inner: Spec
    required: bool = False


@dataclasses.dataclass(frozen=True, slots=True)
class Pattern:
    """Devicetree pattern properties: a mapping from property name to value."""

    pattern: str
    inner: Spec


Spec = Number | Text | Array | Nested | Optional | Pattern


# ---------------------------------------------------------------------------------------------
# Wording


def fmt(value: object, depth: int = 0) -> str:
    """A value as a firmware engineer would write it (1.5, 4.19999981, NaN, inf, 0x600), never longer
    than a line: a message must not format a huge value in full (a YAML alias bomb expands to billions)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if value.is_integer() and abs(value) < 1e16:
            return str(int(value))
        return format(value, ".9g")
    if isinstance(value, int):
        if value.bit_length() > 128:  # str() refuses over 4,300 digits, and no field is that wide
            return f"{'-' if value < 0 else ''}<an integer of {int(value.bit_length() * 0.30103) + 1} digits>"
        return str(value)
    if isinstance(value, bytes | bytearray):
        return repr(bytes(value)) if len(value) <= 40 else f"{bytes(value[:32])!r}... ({len(value)} bytes)"
    if isinstance(value, list | tuple):
        if len(value) <= 8 and depth < 2:  # a matrix row by row; deeper nesting is summarised
            text = "[" + ", ".join(fmt(v, depth + 1) for v in value) + "]"
            return text if len(text) <= 120 else text[:116] + "...]"
        return f"[... {len(value)} items]"
    text = repr(value if len(value) <= 200 else value[:200]) if isinstance(value, str) else brief(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _with_unit(value: object, unit: str) -> str:
    return fmt(value) + (" " + unit if unit else "")


def _names(members: Mapping[int, str], limit: int = 12) -> str:
    items = [f"{name} ({value})" for value, name in sorted(members.items())]
    if len(items) > limit:
        items = [*items[:limit], "..."]
    return ", ".join(items)


def _type_violation(path: str, value: object, expected: str, label: str = "") -> Violation:
    return Violation(path, "type", value, expected, f"{_who(path, label)} = {fmt(value)} is not {expected}")


def _who(path: str, label: str) -> str:
    """How a message names the value: its path, and what its array position holds."""
    return f"{clip(path)}: {label}" if label else clip(path)


# ---------------------------------------------------------------------------------------------
# Diagnosis


def diag(out: list[Violation], path: str, value: object, spec: Spec) -> None:
    """Append every violation of ``value`` (at ``path``) against ``spec``; never raises."""
    if isinstance(spec, Number):
        found = number(path, value, spec)
        if found is not None:
            out.append(found)
    elif isinstance(spec, Array):
        _array(out, path, value, spec)
    elif isinstance(spec, Text):
        found = text(path, value, spec)
        if found is not None:
            out.append(found)
    elif isinstance(spec, Nested):
        _nested(out, path, value, spec)
    elif isinstance(spec, Optional):
        if value is None:
            if spec.required:
                out.append(Violation(path, "required", None, True, f"{clip(path)} is required but missing"))
        else:
            diag(out, path, value, spec.inner)
    else:
        _pattern(out, path, value, spec)


def diagnose(obj: object, fields: tuple[tuple[str, str, Spec], ...]) -> list[Violation]:
    """Every violation of every field of ``obj``, each judged by :func:`diag` (``fields``: schema name,
    attribute, spec): what ``validate()`` falls back to when a fast test meets a value it cannot take."""
    out: list[Violation] = []
    for path, attr, spec in fields:
        diag(out, path, getattr(obj, attr), spec)
    return out


def is_sentinel(value: object, spec: Number) -> bool:
    return _is_marker(value, spec.sentinel)


def _is_marker(value: object, s: float | None) -> bool:
    if s is None or isinstance(value, str):
        return False
    if isinstance(s, float) and math.isnan(s):
        return isinstance(value, float) and math.isnan(value)
    return bool(value == s)


def number(path: str, value: object, spec: Number) -> Violation | None:
    """The first rule ``value`` breaks, most fundamental first: type, NaN, width, range, enum."""
    if is_sentinel(value, spec):
        return None
    unit = spec.unit
    who = _who(path, spec.label)
    kind = spec.kind
    if kind == "bool":
        if isinstance(value, bool) or (isinstance(value, int) and value in (0, 1)):
            return None
        if isinstance(value, int | float):
            return Violation(path, "type-bounds", value, (0, 1), f"{who} = {fmt(value)} is not a bool (0 or 1)")
        return _type_violation(path, value, "a bool", spec.label)
    if kind == "char":
        if isinstance(value, str) and len(value) <= 1 and (not value or ord(value) < 256):
            return None
        return _type_violation(path, value, "a single 8-bit character", spec.label)
    if kind == "float":
        if not isinstance(value, int | float):
            return _type_violation(path, value, f"a number ({spec.type})", spec.label)
        if isinstance(value, float) and math.isnan(value):
            return Violation(
                path,
                "nan",
                value,
                spec.sentinel_text or None,
                f"{who} is NaN, which is not allowed here"
                + (f" (its 'unknown' value is {spec.sentinel_text})" if spec.sentinel_text else ""),
            )
    elif isinstance(value, float):
        if not value.is_integer():
            return _type_violation(path, value, f"an integer ({spec.type})", spec.label)
    elif not isinstance(value, int):
        return _type_violation(path, value, f"an integer ({spec.type})", spec.label)
    assert isinstance(value, int | float)
    if not spec.low <= value <= spec.high:
        if kind == "float":
            if math.isinf(value):
                text = f"{who} = {fmt(value)} is not a finite number"
            else:
                text = (
                    f"{who} = {_with_unit(value, unit)} is beyond the {spec.type} limit "
                    f"±{_with_unit(spec.high, unit)} (it would saturate)"
                )
        else:
            text = f"{who} = {_with_unit(value, unit)} does not fit {spec.type} ({fmt(spec.low)}..{fmt(spec.high)})"
        return Violation(path, "type-bounds", value, (spec.low, spec.high), text)
    low, high = spec.minimum, spec.maximum
    if low is not None and (value <= low if spec.exclusive_minimum else value < low):
        word = "at or below the exclusive minimum" if spec.exclusive_minimum else "below the minimum"
        return Violation(
            path, "range", value, low, f"{who} = {_with_unit(value, unit)} is {word} {_with_unit(low, unit)}"
        )
    if high is not None and (value >= high if spec.exclusive_maximum else value > high):
        word = "at or above the exclusive maximum" if spec.exclusive_maximum else "above the maximum"
        return Violation(
            path, "range", value, high, f"{who} = {_with_unit(value, unit)} is {word} {_with_unit(high, unit)}"
        )
    if spec.values is not None and value not in spec.values:
        return Violation(
            path,
            "enum",
            value,
            tuple(sorted(spec.values)),
            f"{who} = {fmt(value)} is not one of {_names(spec.values)}",
        )
    if spec.mask is not None:
        extra = int(value) & ~spec.mask
        if extra:
            named = [name for bit, name in sorted((spec.bits or {}).items()) if bit & extra]
            what = f" ({', '.join(named)})" if named else ""
            return Violation(
                path,
                "bitmask",
                value,
                spec.mask,
                f"{who} = {int(value):#x} sets undefined or reserved bits {extra:#x}{what}; "
                f"only {spec.mask:#x} may be set",
            )
    return None


def text(path: str, value: object, spec: Text) -> Violation | None:
    who = _who(path, spec.label)
    if not isinstance(value, str):
        return _type_violation(path, value, "a string", spec.label)
    if spec.capacity is not None:
        try:
            size = len(value.encode("utf-8"))
        except UnicodeEncodeError:
            return _type_violation(path, value, "valid UTF-8 text", spec.label)
        if size > spec.capacity:
            return Violation(
                path,
                "length",
                value,
                spec.capacity,
                f"{who} is {size} bytes of UTF-8, more than its {spec.capacity}",
            )
    if spec.const is not None and value != spec.const:
        return Violation(path, "enum", value, spec.const, f"{who} = {brief(value)} must be {spec.const!r}")
    if spec.choices and value not in spec.choices:
        return Violation(
            path,
            "enum",
            value,
            spec.choices,
            f"{who} = {brief(value)} is not one of " + ", ".join(repr(c) for c in spec.choices),  # a value: briefly
        )
    return None


def _array(out: list[Violation], path: str, value: object, spec: Array) -> None:
    if spec.byte and isinstance(value, bytes | bytearray):
        items: Sequence[object] = value[: len(spec.columns)]  # any byte fits uint8: only columns may object
        n = len(value)
    elif isinstance(value, list | tuple):
        items = value
        n = len(value)
    else:
        out.append(_type_violation(path, value, "bytes" if spec.byte else "a list"))
        return
    cap = spec.capacity
    if spec.fixed and cap is not None and n != cap:
        out.append(Violation(path, "length", n, cap, f"{clip(path)} has {n} items, it must have exactly {cap}"))
    elif cap is not None and n > cap:
        out.append(Violation(path, "length", n, cap, f"{clip(path)} has {n} items, more than its capacity {cap}"))
    elif n < spec.min_length:
        out.append(
            Violation(path, "length", n, spec.min_length, f"{clip(path)} has {n} items, fewer than {spec.min_length}")
        )
    if cap is not None:
        items = items[:cap]  # an over-long array is reported once above; its excess is not walked
    if spec.unknown_first is not None and n and _is_marker(value[0], spec.unknown_first):
        return  # the array is unknown: what its other elements hold means nothing
    columns = spec.columns
    for i, item in enumerate(items):
        column = columns[i] if i < len(columns) else None
        diag(out, f"{path}[{i}]", item, spec.element if column is None else column)


def _nested(out: list[Violation], path: str, value: object, spec: Nested) -> None:
    if getattr(value, "QUALIFIED_NAME", None) != spec.type:
        out.append(_type_violation(path, value, f"a {spec.type}"))
        return
    try:
        found = value.validate()  # type: ignore[attr-defined]
    except SLOW as exc:  # a broken instance of a generated class
        out.append(_type_violation(path, value, f"a valid {spec.type} ({exc})"))
        return
    out.extend(prefixed(path, found))


def _pattern(out: list[Violation], path: str, value: object, spec: Pattern) -> None:
    if not isinstance(value, Mapping):
        out.append(_type_violation(path, value, "a mapping of property names to values"))
        return
    for key, item in value.items():
        if not isinstance(key, str) or re.search(spec.pattern, key) is None:
            out.append(
                Violation(
                    str(key),
                    "pattern",
                    key,
                    spec.pattern,
                    f"property name {brief(key)} does not match {spec.pattern}",
                )
            )
            continue
        diag(out, key, item, spec.inner)


def union(out: list[Violation], held: object, values: Mapping[str, object]) -> None:
    """A DroneCAN union: ``union_field`` names one of its branches, and that branch alone holds a value."""
    names = ", ".join(values)
    if not isinstance(held, str) or held not in values:
        message = f"union_field = {fmt(held)} is not a field of this union (one of {names})"
        out.append(Violation("union_field", "union", held, tuple(values), message))
        return
    if values[held] is None:
        out.append(Violation(held, "union", None, held, f"{held} is the selected branch of the union but holds None"))
    others = [name for name, value in values.items() if name != held and value is not None]
    if others:
        message = f"union_field = {held}, yet {', '.join(others)} also hold a value (a union encodes one field)"
        out.append(Violation("union_field", "union", held, tuple(others), message))


def prefixed(path: str, found: Sequence[Violation]) -> list[Violation]:
    """Violations of a nested message, their paths under ``path``."""
    return [
        dataclasses.replace(
            v,
            path=f"{path}.{v.path}",
            message=f"{path}.{v.message}" if v.message.startswith(v.path) else f"{path}: {v.message}",
        )
        for v in found
    ]


def search(pattern: str, key: object) -> bool:
    return isinstance(key, str) and re.search(pattern, key) is not None


def rule(path: str, rule_id: str, value: object, text: str, message: str, severity: str) -> Violation:
    """A broken cross-field rule (see schemas/rules/)."""
    return Violation(path, "cross-field:" + rule_id, value, text, message, severity)


# How many indices a rule's range() covers at most when the message has an unbounded array (devicetree
# tables); over fixed and bounded arrays the generated code passes the schema's largest capacity instead.
SPAN_LIMIT = 1 << 16


def span(start: int, stop: int | None = None, *, limit: int) -> range:
    """A rule's ``range(start, stop)`` kept to the indices ``0..limit`` an array of the schema can have:
    a corrupt count in a record (``cell_count = -10**8``) must not make validate() loop for minutes."""
    if stop is None:
        start, stop = 0, start
    return range(max(start, 0), min(stop, limit))


def entries(value: object) -> list[tuple[str, object]]:
    """A pattern-property mapping's entries in name order (rules iterate tables deterministically)."""
    if not isinstance(value, Mapping):
        raise TypeError("not a mapping")
    return sorted(value.items())
