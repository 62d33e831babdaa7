"""Python source text for the generated converters, laid out as ``ruff format`` lays it out.

The converter generator writes finished text: lines within :data:`WIDTH`, double-quoted strings,
long calls and literals one item per line with a trailing comma (which the formatter keeps),
imports in isort order. Nothing runs a formatter at generation time; the tests check that
``ruff format --check`` and ``ruff check`` pass on ``generated/convert``.
Every value a schema supplies reaches the code through :func:`literal` or :func:`comment`.
"""

from __future__ import annotations

import math
import textwrap
import unicodedata
from collections.abc import Sequence
from dataclasses import dataclass

from ..literals import docstring as _docstring

WIDTH = 120  # the project's line length
INDENT = "    "


def string(text: str | bytes) -> str:
    """A string (or bytes) literal, double-quoted unless that needs more escapes."""
    prefix = "b" if isinstance(text, bytes) else ""
    chars = text.decode("latin-1") if isinstance(text, bytes) else text
    quote = "'" if chars.count('"') > chars.count("'") else '"'
    body = []
    for ch in chars:
        if ch == quote:
            body.append("\\" + ch)
        elif isinstance(text, bytes) and ord(ch) > 0x7E:
            body.append(f"\\x{ord(ch):02x}")
        else:
            body.append(repr(ch)[1:-1] if ch not in "\"'" else ch)
    return f"{prefix}{quote}{''.join(body)}{quote}"


def literal(value: object) -> str:
    """Deterministic source for a scalar, or a tuple, list or dict of them, on one line."""
    if value is None or isinstance(value, bool | int):
        return repr(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "math.nan"
        if math.isinf(value):
            return "math.inf" if value > 0 else "-math.inf"
        return repr(value)
    if isinstance(value, str | bytes):
        return string(value)
    if isinstance(value, tuple):
        inner = ", ".join(literal(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, list):
        return "[" + ", ".join(literal(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{literal(k)}: {literal(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"no literal for {type(value).__name__}")


def number(value: float | int) -> str:
    """A float literal (``math.nan`` for NaN)."""
    return literal(float(value))


def bracketed(head: str, items: list[str], close: str, indent: str, tail: str = "") -> list[str]:
    """``head`` + items + ``close`` + ``tail`` on one line if it fits after ``indent``, else the
    items one per line with a trailing comma. ``head`` ends with the opening bracket."""
    one = f"{indent}{head}{', '.join(items)}{close}{tail}"
    if len(one) <= WIDTH or not items:
        return [one]
    return [f"{indent}{head}", *(f"{indent}{INDENT}{item}," for item in items), f"{indent}{close}{tail}"]


@dataclass
class Call:
    """A call expression kept in parts, so a statement holding it can wrap its arguments."""

    func: str
    args: Sequence[str | Call]

    def __str__(self) -> str:
        return f"{self.func}({', '.join(str(a) for a in self.args)})"


def call(head: str, args: Sequence[str | Call], indent: str, tail: str = "") -> list[str]:
    """A call ``head(args)`` (``head`` may start with an assignment) on one line if it fits, else
    one argument per line with a trailing comma, nested calls wrapped the same way."""
    one = f"{indent}{head}({', '.join(str(a) for a in args)}){tail}"
    if len(one) <= WIDTH or not args:
        return [one]
    lines = [f"{indent}{head}("]
    for arg in args:
        if isinstance(arg, Call):
            lines.extend(call(arg.func, arg.args, indent + INDENT, ","))
        else:
            lines.append(f"{indent}{INDENT}{arg},")
    return [*lines, f"{indent}){tail}"]


def value_lines(head: str, value: object, indent: str = "", tail: str = "") -> list[str]:
    """``head`` followed by a literal: on one line if it fits, else a tuple, list or dict one item
    per line with a trailing comma, items that do not fit split the same way."""
    one = f"{indent}{head}{literal(value)}{tail}"
    if len(one) <= WIDTH or not isinstance(value, tuple | list | dict) or not value:
        return [one]
    inner = indent + INDENT
    if isinstance(value, dict):
        items = [line for k, v in value.items() for line in value_lines(f"{literal(k)}: ", v, inner, ",")]
        return [f"{indent}{head}{{", *items, f"{indent}}}{tail}"]
    opening, closing = ("[", "]") if isinstance(value, list) else ("(", ")")
    items = [line for v in value for line in value_lines("", v, inner, ",")]
    return [f"{indent}{head}{opening}", *items, f"{indent}{closing}{tail}"]


def _clean(text: str) -> str:
    """Schema text as one run of words: no control characters, no line breaks."""
    return " ".join("".join(" " if unicodedata.category(ch)[0] == "C" else ch for ch in text).split())


def comment(text: str, indent: str) -> list[str]:
    """``text`` as ``#`` comment lines within the width (words longer than a line stay whole)."""
    wrapped = textwrap.wrap(_clean(text), WIDTH - len(indent) - 2, break_long_words=False, break_on_hyphens=False)
    return [f"{indent}# {line}" for line in wrapped]


def docstring(text: str, indent: str) -> str:
    """A docstring holding ``text``, its lines wrapped to the width (paragraphs and line breaks kept)."""
    room = WIDTH - len(indent) - 3  # the first line also carries the opening quotes
    lines: list[str] = []
    for line in text.strip("\n").split("\n"):
        lines.extend(textwrap.wrap(line, room, break_long_words=False, break_on_hyphens=False) or [""])
    return _docstring("\n".join(lines), indent)


def imports(names: set[tuple[str, str, str | None]]) -> list[str]:
    """Relative ``from`` imports in isort order: (module, name, alias or None); ``module`` starts
    with dots. Plain names of one module share a statement, aliased ones get their own."""
    plain: dict[str, set[str]] = {}
    statements: list[tuple[tuple[int, str, str], list[str]]] = []
    for module, name, alias in names:
        if alias is None:
            plain.setdefault(module, set()).add(name)
        else:
            statements.append((_import_key(module, name), [f"from {module} import {name} as {alias}"]))
    for module, members in plain.items():
        ordered = sorted(members, key=_member_key)
        one = f"from {module} import {', '.join(ordered)}"
        text = [one] if len(one) <= WIDTH else [f"from {module} import (", *(f"{INDENT}{m}," for m in ordered), ")"]
        statements.append((_import_key(module, ordered[0]), text))
    return [line for _, text in sorted(statements) for line in text]


def _import_key(module: str, first: str) -> tuple[int, str, str]:
    stripped = module.lstrip(".")
    return (-(len(module) - len(stripped)), stripped.lower(), first.lower())


def _member_key(name: str) -> tuple[int, str]:
    """isort's order-by-type: CONSTANTS, then Classes, then everything else."""
    bare = name.lstrip("_")
    rank = 0 if bare.isupper() and len(bare) > 1 else 1 if bare[:1].isupper() else 2
    return rank, name.lower()


def tidy(text: str) -> str:
    """Strip trailing spaces; a module's text ends with one newline."""
    return "\n".join(line.rstrip() for line in text.split("\n")).rstrip("\n") + "\n"


def signature(name: str, params: list[str], returns: str) -> list[str]:
    """A ``def`` line, or the parameters one per line when it does not fit."""
    one = f"def {name}({', '.join(params)}) -> {returns}:"
    if len(one) <= WIDTH:
        return [one]
    return [f"def {name}(", *(f"{INDENT}{p}," for p in params), f") -> {returns}:"]
