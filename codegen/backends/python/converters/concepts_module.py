"""``convert/_concepts.py``: ``BatteryState``, the shared concepts as a dataclass (SI units, None = unknown)."""

from __future__ import annotations

from ....ir import Concept
from .. import naming
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
        "from typing import ClassVar",
        "",
        "from ._state import ConceptState",
        "",
        "",
        "# to_dict() and from_dict() come from ConceptState (runtime/convert/_state.py), over KINDS and CHOICES",
        "@dataclasses.dataclass(slots=True)",
        "class BatteryState(ConceptState):",
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
    return "\n".join(lines) + "\n"
