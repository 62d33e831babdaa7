"""Quoting a value from untrusted data in a message: never longer than a line, never walked whole.

A YAML alias bomb of a few hundred bytes expands to billions of items when repr() or json.dumps walks it,
and an integer of 5,000 digits has no decimal repr at all (Python refuses over 4,300 digits). Messages and
reports quote such values through :func:`brief` and keep them through :func:`reportable`.
"""

from __future__ import annotations

import reprlib

MAX_INT_BITS = 128  # wider integers are described by their size (no field of any format is wider than 64 bits)


def int_text(value: int) -> str:
    """An integer in decimal, or its size when it is too wide to print usefully."""
    if value.bit_length() <= MAX_INT_BITS:
        return str(value)
    return f"{'-' if value < 0 else ''}<an integer of {int(value.bit_length() * 0.30103) + 1} digits>"


class _Brief(reprlib.Repr):
    def __init__(self) -> None:
        super().__init__()
        self.maxlevel = 2
        self.maxlist = self.maxtuple = self.maxdict = self.maxset = 4
        self.maxstring = self.maxother = 60

    def repr_int(self, x: int, level: int) -> str:
        return int_text(x)

    def repr_str(self, x: str, level: int) -> str:
        return super().repr_str(x[:200], level)


_BRIEF = _Brief()


def brief(value: object, width: int = 60) -> str:
    """repr(value) cut to ``width`` characters, nested containers summarised, huge integers by size."""
    text = _BRIEF.repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


PATH_WIDTH = 160  # the generated runtime's _validate.PATH_WIDTH: both cut a path the same way


def clip(path: str, width: int = PATH_WIDTH) -> str:
    """A name or path from the data as a message shows it: whole up to ``width`` characters, else its
    head and tail (a key can be thousands of characters; the tail keeps an item's index)."""
    if len(path) <= width:
        return path
    tail = width // 3
    return path[: width - tail - 3] + "..." + path[-tail:]


def _scalar(v: object) -> bool:
    return (
        v is None
        or isinstance(v, bool | float)
        or (isinstance(v, str) and len(v) <= 200)
        or (isinstance(v, int) and v.bit_length() <= MAX_INT_BITS)
    )


def _row(v: object) -> bool:
    return isinstance(v, list | tuple) and len(v) <= 64 and all(_scalar(x) for x in v)


def reportable(value: object) -> object:
    """``value`` itself when a report (JSON included) can carry it whole -- a scalar, a row of scalars
    (a cell voltage array) or a matrix of such rows (a devicetree OCV table) -- else its :func:`brief` text."""
    if _scalar(value) or _row(value):
        return value
    if isinstance(value, list | tuple) and len(value) <= 64 and all(_row(v) for v in value):
        return value
    return brief(value)
