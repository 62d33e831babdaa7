"""Frontend for Linux devicetree dt-schema bindings (YAML) -> IR.

One binding (``$id: http://devicetree.org/schemas/power/supply/battery.yaml#``) becomes one
Message ``devicetree.power.supply.battery``; each entry of ``properties`` / ``patternProperties``
becomes a Field.  Sub-nodes described inline become messages of their own, named below the parent.

Type choices: a ``flag`` (present or absent, no value) is ``bool`` of 1 bit; a phandle is a
``uint32`` cell annotated ``("dt-phandle", ...)``; a property whose type nothing states is its raw
bytes (``uint8[]``) annotated ``("dt-type", "unknown")``.  Every field carries ``("dt-type", name)``
with the types.yaml name, and ``("dt-type-source", how)`` saying what decided it.  An ``items``
list (per-position schemas) becomes the array type's ``columns`` (see :mod:`.columns`).

The work is done in: :mod:`.binding` (a binding -> messages and fields), :mod:`.refs` (which
types.yaml type a property has), :mod:`.shape` (dimensions, IR type, value constraints),
:mod:`.columns` (per-position constraints) and :mod:`.data` (types.yaml, property-units.yaml).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...errors import ErrorCollector, SchemaError
from ...ir import Message, Schema
from ...text.files import display_path
from ...text.limits import read_schema_text
from ...text.yaml_lines import load
from .binding import binding_messages, is_binding
from .data import DATA_FILES, load_data

__all__ = ["is_binding", "parse_dir", "parse_file"]


def _load(path: Path, root: Path | None) -> tuple[Any, str]:
    display = display_path(path, root)
    return load(read_schema_text(path, display), display), display


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One binding; types.yaml and property-units.yaml come from ``root`` (else the file's folder)."""
    doc, display = _load(path, root)
    messages = binding_messages(doc, display, load_data(root if root is not None else path.parent))
    return Schema(messages=tuple(sorted(messages, key=lambda m: m.qualified_name)), sources=(display,))


def parse_dir(root: Path) -> Schema:
    """Every binding (``*.yaml`` with an $id and properties) below ``root``, in sorted path order."""
    data = load_data(root)
    messages: list[Message] = []
    sources: list[str] = []
    found = ErrorCollector()  # every file's errors in one report
    for path in sorted(root.rglob("*.yaml")):
        if path.parent.resolve() == root.resolve() and path.name in DATA_FILES:
            continue
        with found.step():
            doc, display = _load(path, root)
            if is_binding(doc):
                messages += binding_messages(doc, display, data)
                sources.append(display)
    found.raise_if_any()
    seen: dict[str, str] = {}
    for m in messages:
        if m.qualified_name in seen:
            raise SchemaError(
                m.location.file, m.location.line, f"expected a unique $id; {seen[m.qualified_name]} has it"
            )
        seen[m.qualified_name] = str(m.location)
    return Schema(messages=tuple(sorted(messages, key=lambda m: m.qualified_name)), sources=tuple(sources))
