"""Field comment metadata of uORB messages (PX4's "uORB Documentation Standard").

A field comment starts with bracketed metadata, then free text::

    float32 remaining  # [@range 0,1] [@invalid -1] Remaining capacity

``[unit]`` (no ``@``) is the unit; ``[@range lo, hi]`` (either side may be empty),
``[@invalid value description]``, ``[@enum PREFIX ...]`` and ``[@frame NAME]`` are tags.
Tags this frontend does not interpret are kept verbatim in ``Field.annotations``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

from ...errors import SchemaError
from ...ir import PrimitiveKind, PrimitiveType, Range, Sentinel
from .values import fits, parse_number

_TAG = re.compile(r"@([A-Za-z_][A-Za-z0-9_]*)(?:\s+(.*))?\Z", re.S)
_ENUM_PREFIX = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_MAPPED = ("range", "invalid", "enum")  # tags turned into IR fields rather than kept verbatim
_NEEDS_TEXT = frozenset({*_MAPPED, "frame"})


@dataclass(frozen=True)
class FieldNotes:
    """What a field comment says, before it is checked against the field's type."""

    doc: str
    unit_text: str | None = None
    range: Range | None = None
    invalid: tuple[str, str] | None = None  # (value as written, optional description)
    enums: tuple[str, ...] = ()  # enum prefixes, unqualified
    annotations: tuple[tuple[str, str], ...] = ()


def parse_comment(comment: str, file: str, line: int) -> FieldNotes:
    rest = comment.strip()
    unit: str | None = None
    tags: dict[str, str] = {}
    kept: list[tuple[str, str]] = []
    while rest.startswith("["):
        end = rest.find("]")
        if end < 0:
            raise SchemaError(file, line, "expected ']' to close the '[' metadata in the comment")
        content, rest = rest[1:end].strip(), rest[end + 1 :].lstrip()
        if not content.startswith("@"):
            if not content:
                raise SchemaError(file, line, "expected a unit inside '[]' (use '[-]' for unitless)")
            if unit is not None:
                raise SchemaError(file, line, f"expected one unit, got '[{unit}]' and '[{content}]'")
            unit = content
            continue
        match = _TAG.match(content)
        if not match:
            raise SchemaError(file, line, f"expected a tag name after '@' in '[{content}]'")
        tag, text = match.group(1), (match.group(2) or "").strip()
        if tag in _NEEDS_TEXT and not text:
            raise SchemaError(file, line, f"expected a value after '@{tag}'")
        if tag in _MAPPED:
            if tag in tags:
                raise SchemaError(file, line, f"expected one '[@{tag} ...]' per field")
            tags[tag] = text
        else:
            kept.append((tag, text))
    invalid = None
    if "invalid" in tags:
        value, *description = tags["invalid"].split(None, 1)
        invalid = (value, description[0].strip() if description else "")
        if invalid[1]:
            kept.append(("invalid", tags["invalid"]))
    return FieldNotes(
        doc=rest.strip(),
        unit_text=unit,
        range=_range(tags["range"], file, line) if "range" in tags else None,
        invalid=invalid,
        enums=_enum_prefixes(tags["enum"], file, line) if "enum" in tags else (),
        annotations=tuple(kept),
    )


def _range(text: str, file: str, line: int) -> Range:
    expected = f"expected '[@range <min>, <max>]' with numbers (either side may be empty), got '[@range {text}]'"
    parts = text.split(",")
    if len(parts) != 2:
        raise SchemaError(file, line, expected)
    bounds: list[int | float | None] = []
    for part in parts:
        part = part.strip()
        value = parse_number(part) if part else None
        if part and (value is None or math.isnan(value)):
            raise SchemaError(file, line, expected)
        bounds.append(value)
    low, high = bounds
    if low is None and high is None:
        raise SchemaError(file, line, f"expected at least one bound in '[@range {text}]'")
    if low is not None and high is not None and low > high:
        raise SchemaError(file, line, f"expected min <= max in '[@range {text}]'")
    return Range(minimum=low, maximum=high)


def _enum_prefixes(text: str, file: str, line: int) -> tuple[str, ...]:
    names: list[str] = []
    for name in text.split():
        if not _ENUM_PREFIX.match(name):
            raise SchemaError(file, line, f"expected constant name prefixes after '@enum', got '{name}'")
        if name not in names:
            names.append(name)
    return tuple(names)


def sentinel(
    text: str,
    element: PrimitiveType | None,
    per_element: bool,
    constants: Mapping[str, int | float | bool],
    file: str,
    line: int,
) -> Sentinel:
    """The ``[@invalid text]`` value of a field whose elements are ``element`` (None: not numeric)."""
    if element is None:
        raise SchemaError(file, line, "expected '@invalid' only on numeric or bool fields")
    value: int | float | None
    if element.kind is PrimitiveKind.BOOL and text.lower() in ("true", "false"):
        value = int(text.lower() == "true")
    elif text in constants:
        value = int(constants[text]) if isinstance(constants[text], bool) else constants[text]
    else:
        value = parse_number(text)
    if value is None:
        raise SchemaError(
            file, line, f"expected a number, NaN or a limit name such as INT16_MAX after '@invalid', got '{text}'"
        )
    if not fits(element, value):
        raise SchemaError(file, line, f"expected an '@invalid' value a {element.name} can hold, got '{text}'")
    value = float(value) if element.kind is PrimitiveKind.FLOAT else int(value)
    return Sentinel(value=value, text=text, per_element=per_element)
