"""Python source literals for schema-supplied values: everything a schema says reaches generated
code only through these functions, so no name, comment or value can break out of a literal.

Literals are Python's own ``repr`` (ruff then spells them its way: double quotes, upper-case hex
digits), and long text is cut into implicitly concatenated parts that ruff can put on lines of
their own.
"""

from __future__ import annotations

import math
import textwrap
import unicodedata

from .formatting import LINE_LENGTH

TEXT_PART = 80  # characters of text per part of a long string literal


def py_literal(value: object) -> str:
    """Deterministic Python source for a scalar (bytes too), or a tuple, list or dict of them."""
    if value is None or isinstance(value, bool):
        return repr(value)
    if isinstance(value, int):
        return repr(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "_math.nan"
        if math.isinf(value):
            return "_math.inf" if value > 0 else "-_math.inf"
        return repr(value)
    if isinstance(value, str | bytes):
        return repr(value)
    if isinstance(value, tuple):
        inner = ", ".join(py_literal(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, list):
        return "[" + ", ".join(py_literal(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{py_literal(k)}: {py_literal(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"no literal for {type(value).__name__}")


def float_literal(value: float | int) -> str:
    """A number as a float literal, whatever type it came as (``_math.nan`` for NaN)."""
    return py_literal(float(value))


def unparenthesized(source: str) -> str:
    """An expression's source without the parentheses around all of it, where it stands alone (a
    statement's value, a generator's element). Emitters build conditions wrapped in one pair; a
    bracket inside a string literal at worst keeps that pair."""
    if not source.startswith("("):
        return source
    depth = 0
    for i, ch in enumerate(source):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0:
            return source[1:-1] if i == len(source) - 1 else source
    return source


def hex_literal(value: int) -> str:
    """``2047`` -> ``0x7FF`` (bit masks read better in hex)."""
    return ("-" if value < 0 else "") + "0x" + format(abs(value), "X")


def text_literal(text: str) -> str:
    """A string literal for text that may be long (documentation, a struct format): implicitly
    concatenated parts of at most :data:`TEXT_PART` characters, each cut after a space or a
    newline where there is one, so that ruff can put the parts on lines of their own."""
    if len(text) <= TEXT_PART:
        return py_literal(text)
    parts: list[str] = []
    rest = text
    while len(rest) > TEXT_PART:
        window = rest[:TEXT_PART]
        cut = window.rfind("\n") + 1 or window.rfind(" ") + 1 or TEXT_PART
        parts.append(rest[:cut])
        rest = rest[cut:]
    if rest:
        parts.append(rest)
    return " ".join(py_literal(p) for p in parts)


def comment(text: str, indent: str) -> list[str]:
    """``text`` as ``#`` comment lines after ``indent``, wrapped at spaces to the line length (a
    word longer than a line stays whole). Line breaks and control characters become spaces, so
    the text cannot leave the comment."""
    words = " ".join("".join(" " if unicodedata.category(ch)[0] == "C" else ch for ch in text).split())
    width = LINE_LENGTH - len(indent) - 2
    return [f"{indent}# {line}" for line in textwrap.wrap(words, width, break_long_words=False, break_on_hyphens=False)]


def _clean(text: str) -> str:
    # Control and format characters (other than newline/tab) would be invisible or break a line.
    return "".join(
        ch if ch in "\n\t" or unicodedata.category(ch)[0] != "C" else f"\\x{ord(ch):02x}" if ord(ch) < 256 else " "
        for ch in text
    )


def _wrapped(line: str, width: int) -> list[str]:
    """A docstring line cut at spaces to fit ``width`` (a single long word stays whole)."""
    if len(line) <= width:
        return [line]
    lead = line[: len(line) - len(line.lstrip(" "))]
    return textwrap.wrap(
        line,
        width,
        subsequent_indent=lead,
        break_long_words=False,
        break_on_hyphens=False,
        drop_whitespace=True,
    ) or [line]


def docstring(text: str, indent: str) -> str:
    """A triple-quoted docstring holding ``text``, safe whatever the text contains; lines longer
    than the line length allows are wrapped at spaces."""
    body = _clean(text.strip("\n")).replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    width = LINE_LENGTH - len(indent)
    lines: list[str] = []
    for i, line in enumerate(body.splitlines()):
        lines += _wrapped(line.rstrip(), width - (3 if i == 0 else 0))
    body = "\n".join(lines)
    if body.endswith('"'):
        body += " "
    if "\n" not in body and len(indent) + len(body) + 6 <= LINE_LENGTH:
        return f'{indent}"""{body}"""'
    lines = body.split("\n")
    out = [f'{indent}"""{lines[0]}']
    out.extend(f"{indent}{line}" if line else "" for line in lines[1:])
    out.append(f'{indent}"""')
    return "\n".join(out)
