# Copied by battgen from codegen/backends/python/runtime/convert/_state.py; do not edit here, edit it there.
"""Run-time support of the generated ``BatteryState``: plain data in and out, checked against each
concept's kind.

The generated class (``convert/_concepts.py``) holds what varies per set of concepts (the fields,
``KINDS``, ``CHOICES``, ``UNITS``); this base holds what does not. Standard library only: this file
is copied verbatim into ``generated/convert/_state.py``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar, Self

from ._runtime import ConversionError


class ConceptState:
    """Base of a generated state class: ``to_dict`` and ``from_dict`` over its ``KINDS``."""

    __slots__ = ()  # the generated dataclass declares the slots

    KINDS: ClassVar[dict[str, str]] = {}
    CHOICES: ClassVar[dict[str, tuple[str, ...]]] = {}

    def to_dict(self) -> dict[str, Any]:
        """Plain data keyed by concept name (lists for cells and flags, None for unknown)."""
        out: dict[str, Any] = {}
        for name in self.KINDS:
            value = getattr(self, name)
            out[name] = list(value) if isinstance(value, tuple) else value
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Self:
        """Build from plain data; unknown keys and ill-typed values raise ConversionError."""
        obj = cls()
        for name, value in data.items():
            kind = cls.KINDS.get(name)
            if kind is None:
                raise ConversionError(f"{name}: not a battery concept")
            choices = cls.CHOICES.get(name, ())
            setattr(obj, name, None if value is None else _coerce(name, kind, value, choices))
        return obj


def _coerce(name: str, kind: str, value: Any, choices: tuple[str, ...]) -> Any:
    if kind == "number" and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    if kind == "number" and value in ("NaN", "nan"):
        return math.nan
    if kind == "integer" and isinstance(value, int) and not isinstance(value, bool):
        return value
    if kind == "bool" and isinstance(value, bool):
        return value
    if kind == "text" and isinstance(value, str):
        return value
    if kind == "choice" and value in choices:
        return value
    if kind == "list" and isinstance(value, list | tuple):
        return tuple(_coerce(name, "number", v, ()) for v in value)
    if kind == "flags" and isinstance(value, list | tuple) and all(v in choices for v in value):
        return tuple(c for c in choices if c in value)
    raise ConversionError(f"{name}: expected a {kind} value, got {value!r}")
