"""ArduPilot parameter metadata frontend: ``*.pdef.xml`` (the apm.pdef.xml ground stations read) -> IR.

The file is what ArduPilot's param_parse.py emits::

    <paramfile><vehicles>/<libraries>
      <parameters name="BATT_">
        <param name="BATT_LOW_VOLT" humanName="..." documentation="..." user="Standard">
          <field name="Units">V</field> <field name="Range">0 30</field> <field name="Increment">0.1</field>
          <values><value code="0">None</value>...</values>           (or <field name="Values">0:None,...)
          <bitmask><bit code="0">...</bit>...</bitmask>             (or <field name="Bitmask">0:...,1:...)

Each <parameters> group becomes one Message ``params.<group>`` (:mod:`.groups`), each <param> a
Field (:mod:`.parameter`), typed from its Range, Values, Bitmask or our optional ``Type`` and
``Default`` fields (:mod:`.values`). The file is read into a line-numbered tree (:mod:`.tree`)
with the shared hardened XML set-up: DTDs and entities are refused.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import ErrorCollector, SchemaError
from ...ir import Message, Schema
from ...text.files import display_path
from .groups import group_messages
from .tree import read_tree

__all__ = ["parse_dir", "parse_file"]

SUFFIX = ".pdef.xml"


def parse_file(path: Path, *, root: Path | None = None) -> Schema:
    """One apm.pdef.xml-style file: every <parameters> group in it."""
    display = display_path(path, root)
    messages = group_messages(read_tree(path, display))
    return Schema(messages=tuple(sorted(messages, key=lambda m: m.qualified_name)), sources=(display,))


def parse_dir(root: Path) -> Schema:
    """Every ``*.pdef.xml`` below ``root``, in sorted path order."""
    if not root.is_dir():
        raise SchemaError(display_path(root, None), 0, f"expected a directory of {SUFFIX} files")
    schema = Schema()
    found = ErrorCollector()  # every file's errors in one report
    for path in sorted(root.rglob("*" + SUFFIX)):
        if path.is_file():
            with found.step():
                schema = schema.merged(parse_file(path, root=root))
    found.raise_if_any()
    seen: dict[str, Message] = {}
    for msg in schema.messages:
        if msg.qualified_name in seen:
            first = seen[msg.qualified_name].location
            raise SchemaError(
                msg.location.file,
                msg.location.line,
                f"expected one definition of {msg.qualified_name} (also at {first})",
            )
        seen[msg.qualified_name] = msg
    return Schema(messages=tuple(sorted(schema.messages, key=lambda m: m.qualified_name)), sources=schema.sources)
