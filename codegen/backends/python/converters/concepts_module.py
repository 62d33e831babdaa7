"""``convert/_concepts.py``: ``BatteryState``, the shared concepts as a dataclass (SI units, None = unknown)."""

from __future__ import annotations

from ....ir import Concept
from .. import naming
from ..layout import format_module
from ..literals import docstring, py_literal
from .context import INDENT

_KIND_TYPES = {
    "number": "float | None",
    "integer": "int | None",
    "bool": "bool | None",
    "text": "str | None",
    "list": "tuple[float, ...] | None",
    "choice": "str | None",
    "flags": "tuple[str, ...] | None",
}

# BatteryState's methods and the value check they use: the same for every set of concepts
_METHODS = '''
    def to_dict(self) -> dict[str, Any]:
        """Plain data keyed by concept name (lists for cells and flags, None for unknown)."""
        out: dict[str, Any] = {}
        for name in self.KINDS:
            value = getattr(self, name)
            out[name] = list(value) if isinstance(value, tuple) else value
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> BatteryState:
        """Build from plain data; unknown keys and ill-typed values raise ConversionError."""
        obj = cls()
        for name, value in data.items():
            kind = cls.KINDS.get(name)
            if kind is None:
                raise _r.ConversionError(f"{name}: not a battery concept")
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
    raise _r.ConversionError(f"{name}: expected a {kind} value, got {value!r}")
'''


def concepts_module(concepts: dict[str, Concept], header: str) -> str:
    units = {c.name: c.unit.symbol if c.unit else None for c in concepts.values()}
    kinds = {c.name: c.kind for c in concepts.values()}
    choices = {c.name: c.choices for c in concepts.values() if c.choices}
    lines = [
        header,
        docstring(
            "The shared battery state every format converts to and from: SI units, None for unknown.\n\n"
            "The battery failsafe evaluates battery data from any format through it.",
            "",
        ),
        "",
        "from __future__ import annotations",
        "",
        "import dataclasses",
        "import math",
        "from collections.abc import Mapping",
        "from typing import Any, ClassVar",
        "",
        "from . import _runtime as _r",
        "",
        "",
        "@dataclasses.dataclass(slots=True)",
        "class BatteryState:",
        docstring("One battery's state in the shared concepts (see schemas/mappings/concepts.yaml).", INDENT),
        "",
        f"{INDENT}UNITS: ClassVar[dict[str, str | None]] = {py_literal(units)}",
        f"{INDENT}KINDS: ClassVar[dict[str, str]] = {py_literal(kinds)}",
        f"{INDENT}CHOICES: ClassVar[dict[str, tuple[str, ...]]] = {py_literal(choices)}",
        "",
    ]
    for c in concepts.values():
        unit = f" [{c.unit.symbol}]" if c.unit else ""
        lines.append(f"{INDENT}{naming.identifier(c.name)}: {_KIND_TYPES[c.kind]} = None")
        lines.append(docstring(f"{c.doc}{unit}", INDENT))
    return format_module("\n".join(lines) + "\n" + _METHODS)
