"""The import block of a generated module, ordered as isort (ruff's ``I`` rules) orders it."""

from __future__ import annotations

import re
from collections.abc import Iterable

_FROM = re.compile(r"from (\S+) import (\S+)(?: as (\S+))?$")


def _module_key(module: str) -> tuple[int, str]:
    dots = len(module) - len(module.lstrip("."))
    return (-dots, module[dots:])  # the furthest relative module first


def from_imports(lines: Iterable[str]) -> list[str]:
    """``from X import Y [as Z]`` lines of one section: modules in order, one line per aliased
    name, the plain names of a module joined into one line (at the place of the first of them)."""
    by_module: dict[str, set[tuple[str, str | None]]] = {}
    for line in lines:
        match = _FROM.match(line.strip())
        if match is None:
            raise ValueError(f"not a single-name from-import: {line!r}")
        module, name, alias = match.groups()
        by_module.setdefault(module, set()).add((name, alias))
    out: list[str] = []
    for module in sorted(by_module, key=_module_key):
        plain = sorted(name for name, alias in by_module[module] if alias is None)
        done_plain = False
        for name, alias in sorted(by_module[module], key=lambda e: (e[0], e[1] or "")):
            if alias is not None:
                out.append(f"from {module} import {name} as {alias}")
            elif not done_plain:
                out.append(f"from {module} import {', '.join(plain)}")
                done_plain = True
    return out
