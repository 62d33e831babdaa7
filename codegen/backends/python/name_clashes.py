"""Definitions the generated package cannot tell apart: refused before anything is written.

``Battery.msg``, ``battery.msg`` and ``BATTERY.msg`` all generate the class ``uorb.Battery`` (and the ULog
topic ``battery``); MAVLink's ``FOO_BAR`` and ``FOO__BAR`` both generate ``FooBar``. Written as they come,
the last would silently replace the others. Two modules whose files differ only by case (DSDL namespaces
``Power`` and ``power``) would be one file on a case-insensitive file system (macOS, Windows).
"""

from __future__ import annotations

from ...errors import BattgenError, ErrorList, SchemaError
from ...ir import Message, Schema
from . import naming


def clashes(schema: Schema) -> list[BattgenError]:
    """One error per definition whose generated class, or module file, another one already has: at the
    later definition, naming the earlier one's file and line."""
    errors: list[BattgenError] = []
    classes: dict[tuple[str, str], Message] = {}
    modules: dict[str, tuple[str, Message]] = {}  # module path in lower case -> (its spelling, first message)
    for msg in schema.messages:
        module, name = naming.module_path(msg), naming.class_name(msg)
        first = classes.setdefault((module, name), msg)
        if first is not msg:
            errors.append(
                SchemaError(
                    msg.location.file,
                    msg.location.line,
                    f"expected a name of its own: {msg.qualified_name} generates the class {module}.{name}, as "
                    f"{first.qualified_name} ({first.location}) does (names that differ only by case or "
                    "underscores collide)",
                )
            )
        spelled, owner = modules.setdefault(module.lower(), (module, msg))
        if spelled != module:
            errors.append(
                SchemaError(
                    msg.location.file,
                    msg.location.line,
                    f"expected a namespace of its own: {msg.qualified_name} generates the module {module}, which "
                    f"differs only by case from {spelled} of {owner.qualified_name} ({owner.location}): one file "
                    "on a case-insensitive file system",
                )
            )
    return errors


def refuse_clashes(schema: Schema) -> None:
    """Raise every clash of ``schema`` (:func:`clashes`) at once."""
    ErrorList.raise_if_any(clashes(schema))
