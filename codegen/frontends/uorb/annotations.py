"""Field comment metadata of uORB messages (PX4's "uORB Documentation Standard").

A field comment starts with bracketed metadata, then free text::

    float32 remaining  # [@range 0,1] [@invalid -1] Remaining capacity

``[unit]`` (no ``@``) is the unit; ``[@range lo, hi]`` (either side may be empty),
``[@invalid value description]``, ``[@enum PREFIX ...]`` and ``[@frame NAME]`` are tags.
Tags this frontend does not interpret are kept verbatim in ``Field.annotations``.

PX4's generator ignores comments, so every spelling found in PX4's own files is read, the odd ones
with a warning where PX4's doc linter (Tools/msg/generate_msg_docs.py) flags them too:

* a range bound may be ``pi`` (π), ``2*pi`` or ``pi/2``, and may carry words: ``-1 (Left)``; the
  words join the field's doc;
* a frame written like a unit, ``[m/s^2] [FRD]``, is the frame (warning ``frame-as-unit``: the
  linter reports it as an unknown unit);
* a range written without ``@``, ``[m/s] [-inf, inf]`` (PX4 1.16), is the range (warning
  ``range-without-at``).
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Mapping
from dataclasses import dataclass

from ...errors import SchemaError
from ...ir import PrimitiveKind, PrimitiveType, Range, Sentinel
from .values import fits, parse_number

_TAG = re.compile(r"@([A-Za-z_][A-Za-z0-9_]*)(?:\s+(.*))?\Z", re.S)
_ENUM_PREFIX = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_MAPPED = ("range", "invalid", "enum", "frame")  # tags turned into IR fields rather than kept verbatim
_NEEDS_TEXT = frozenset(_MAPPED)
# frame names PX4's messages use; written bare (``[FRD]``) they are a frame, not a unit
FRAME_NAMES = frozenset({"NED", "ENU", "FRD", "FLU", "NWU", "ECEF", "Body", "BODY"})
# a range bound: a number or a multiple of pi, optionally followed by words in parentheses
_BOUND = re.compile(r"(?P<value>[^()]*?)\s*(?:\((?P<words>[^()]*)\))?\Z")
_PI = re.compile(
    r"(?P<sign>[+-]?)(?:(?P<factor>[0-9]+(?:\.[0-9]*)?)\s*\*\s*)?pi(?:\s*/\s*(?P<divisor>[0-9]+))?\Z", re.I
)
# an '@invalid' on a char array that means the empty string (all bytes zero)
_EMPTY_TEXT = frozenset({"0", "empty"})


@dataclass(frozen=True)
class FieldNotes:
    """What a field comment says, before it is checked against the field's type."""

    doc: str
    unit_text: str | None = None
    range: Range | None = None
    invalid: tuple[str, str] | None = None  # (value as written, optional description)
    enums: tuple[str, ...] = ()  # enum prefixes, unqualified
    annotations: tuple[tuple[str, str], ...] = ()
    frame: str | None = None
    warnings: tuple[tuple[str, str], ...] = ()  # (kind, message)


def parse_comment(comment: str, file: str, line: int, *, float32: bool = False) -> FieldNotes:
    """The metadata of a field comment; ``float32``: a ``pi`` range bound is C's ``M_PI_F``."""
    rest = comment.strip()
    unit: str | None = None
    tags: dict[str, str] = {}
    kept: list[tuple[str, str]] = []
    warnings: list[tuple[str, str]] = []
    while rest.startswith("["):
        end = rest.find("]")
        if end < 0:
            raise SchemaError(file, line, "expected ']' to close the '[' metadata in the comment")
        content, rest = rest[1:end].strip(), rest[end + 1 :].lstrip()
        if not content.startswith("@"):
            if not content:
                raise SchemaError(file, line, "expected a unit inside '[]' (use '[-]' for unitless)")
            bare = _bare_tag(content)
            if bare is not None:
                if bare in tags:
                    raise SchemaError(file, line, f"expected one '[@{bare} ...]' per field, got also '[{content}]'")
                tags[bare] = content
                kind, template = _BARE_WARNINGS[bare]
                warnings.append((kind, template.format(content)))
                continue
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
    doc = rest.strip()
    bounds = None
    if "range" in tags:
        bounds, words, symbolic = _range(tags["range"], file, line, float32)
        if symbolic:  # keep what the source wrote where the IR's two numbers say less
            kept.append(("range", tags["range"]))
        if words:
            doc = f"{doc} ({words})" if doc else words
    return FieldNotes(
        doc=doc,
        unit_text=unit,
        range=bounds,
        invalid=invalid,
        enums=_enum_prefixes(tags["enum"], file, line) if "enum" in tags else (),
        annotations=tuple(kept),
        frame=tags.get("frame"),
        warnings=tuple(warnings),
    )


def _bare_tag(content: str) -> str | None:
    """The tag a bracket without '@' stands for: a range ``[-inf, inf]``, a frame ``[FRD]``, else None."""
    if "," in content:
        return "range"
    if content in FRAME_NAMES:
        return "frame"
    return None


# (warning kind, message template) for a bracket without '@' read as a tag
_BARE_WARNINGS = {
    "range": ("range-without-at", "read '[{0}]' as the range '[@range {0}]' (PX4 writes ranges with '@range')"),
    "frame": (
        "frame-as-unit",
        "read '[{0}]' as the frame '[@frame {0}]', not as a unit (PX4's doc linter reports an unknown unit)",
    ),
}


def _range(text: str, file: str, line: int, float32: bool) -> tuple[Range, str, bool]:
    """(range, the bounds' words for the doc, whether a bound was not a plain number)."""
    expected = (
        "expected '[@range <min>, <max>]' with numbers or multiples of pi, each optionally followed by words "
        f"in parentheses (either side may be empty), got '[@range {text}]'"
    )
    parts = text.split(",")
    if len(parts) != 2:
        raise SchemaError(file, line, expected)
    bounds: list[int | float | None] = []
    words: list[str] = []
    symbolic = False
    for part in parts:
        match = _BOUND.match(part.strip())
        if not match:
            raise SchemaError(file, line, expected)
        written, said = match.group("value").strip(), (match.group("words") or "").strip()
        value = parse_number(written) if written else None
        if value is None and written:
            value = _multiple_of_pi(written, float32)
            symbolic = True
        if (written and (value is None or math.isnan(value))) or (said and not written):
            raise SchemaError(file, line, expected)
        if said:
            words.append(f"{written}: {said}")
            symbolic = True
        bounds.append(value)
    low, high = bounds
    if low is None and high is None:
        raise SchemaError(file, line, f"expected at least one bound in '[@range {text}]'")
    if low is not None and high is not None and low > high:
        raise SchemaError(file, line, f"expected min <= max in '[@range {text}]'")
    return Range(minimum=low, maximum=high), "; ".join(words), symbolic


def _multiple_of_pi(text: str, float32: bool) -> float | None:
    """``pi``, ``-pi``, ``2*pi``, ``pi/2``: π as a float64, or as C's float ``M_PI_F`` in a float32
    field (rounded to float32, a hair above π), so that a float32 value of exactly ±π is in range."""
    match = _PI.match(text)
    if not match:
        return None
    value = math.pi * float(match.group("factor") or 1) / float(match.group("divisor") or 1)
    if float32:
        bits: int = struct.unpack("<I", struct.pack("<f", value))[0]
        rounded: float = struct.unpack("<f", struct.pack("<I", bits))[0]
        if rounded < value:  # round away from zero: the next float32 up
            rounded = struct.unpack("<f", struct.pack("<I", bits + 1))[0]
        value = rounded
    return -value if match.group("sign") == "-" else value


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


def text_sentinel(text: str, file: str, line: int) -> tuple[Sentinel, tuple[str, str] | None]:
    """The ``[@invalid ...]`` of a char array: ``0`` (all bytes zero, as PX4's BatteryInfo says) or
    ``empty``, both the empty string: in the IR the byte value 0 per element. ``empty`` comes with
    the warning PX4's doc linter gives (it knows only ``NaN`` and ``0``)."""
    if text.lower() not in _EMPTY_TEXT:
        raise SchemaError(
            file, line, f"expected '[@invalid 0]' (all bytes zero: an empty string) on a char array, got '{text}'"
        )
    warning = None
    if text != "0":
        warning = ("invalid-value", f"read '@invalid {text}' on a char array as the empty string ('@invalid 0')")
    return Sentinel(value=0, text=text, per_element=True), warning
