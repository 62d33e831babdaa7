"""Local names for the message classes a generated converter module imports."""

from __future__ import annotations

from collections.abc import Iterable

from ....ir import Schema
from .. import naming
from ..imports import from_imports

Import = tuple[str, str, str | None]  # (relative module, name, alias or None)


def import_lines(names: Iterable[Import]) -> list[str]:
    """The ``from`` imports binding ``names``, in isort order (one statement a line: ruff
    breaks the long ones)."""
    return from_imports(f"from {m} import {name}" + (f" as {alias}" if alias else "") for m, name, alias in names)


def class_names(
    schema: Schema, qualified: Iterable[str], taken: Iterable[str] = ()
) -> tuple[dict[str, str], set[Import]]:
    """A name per message (qualified name -> local name) and the imports binding them.

    A class keeps its own name (``BatteryInfo``) unless two messages of the module share it, or
    it would shadow a name in ``taken``: then its format goes in front (``UorbBatteryStatus``).
    """
    wanted = list(dict.fromkeys(qualified))
    own = {q: naming.class_name(schema.message(q)) for q in wanted}
    used = set(taken)
    names: dict[str, str] = {}
    imports: set[Import] = set()
    for q in wanted:
        msg = schema.message(q)
        cls = own[q]
        module = ".." + naming.module_path(msg)
        if list(own.values()).count(cls) == 1 and cls not in used:
            names[q] = cls
            imports.add((module, cls, None))
        else:
            alias = naming.camel(msg.format.value) + cls
            if alias in used or alias in own.values():
                alias = "_" + naming.identifier(q.replace(".", "_"))
            names[q] = alias
            imports.add((module, cls, alias))
        used.add(names[q])
    return names, imports
