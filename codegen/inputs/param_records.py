"""Parameter files (.param / .parm / .params) as records for ``battgen validate``.

One record per parameter set: the whole of an ArduPilot .param file, one per (vehicle, component)
of a QGroundControl .params file. A record holds the parameters the message models (a full dump's
other parameters are dropped, see :func:`codegen.inputs.paramfile.select`); sets holding none of them are
skipped, with one notice when the whole file holds none. A violation points at its parameter's line.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from ..ir import Message
from . import paramfile
from .records import Item, Notice, Record, split_path


def _names(model: Any) -> set[str]:
    return {f.metadata.get("name", f.name) for f in dataclasses.fields(model)}


def _locator(lines: dict[str, int]) -> Callable[[str], int | None]:
    def locate(path: str) -> int | None:
        tokens = split_path(path)
        return lines.get(tokens[0]) if tokens else None

    return locate


def read_params(path: Path, name: str, message: Message, model: Any) -> Iterator[Item]:
    """The parameter sets of one file (ParamFileError names file and line when it is malformed)."""
    entries = paramfile.load(path, name)  # read eagerly: a malformed file fails before any record
    return _records(entries, name, message, _names(model))


def _records(entries: list[paramfile.ParamEntry], name: str, message: Message, names: set[str]) -> Iterator[Item]:
    groups: dict[tuple[int | None, int | None], list[paramfile.ParamEntry]] = {}
    for entry in entries:
        groups.setdefault((entry.vehicle, entry.component), []).append(entry)
    index = 0
    for (vehicle, component), group in groups.items():
        chosen = [e for e in group if e.name in names]
        if not chosen:
            continue  # e.g. a gimbal's parameters in a QGC file: nothing of this message
        lines = {e.name: e.line for e in chosen}
        qgc = vehicle is not None
        yield Record(
            index,
            chosen[0].line,
            {e.name: e.value for e in chosen},
            name,
            where=f"vehicle {vehicle} component {component}" if qgc else "",
            locate=_locator(lines),
            location={"vehicle": vehicle, "component": component} if qgc else None,
        )
        index += 1
    if index == 0:
        yield Notice(
            name,
            f"no parameter of {message.qualified_name} in this file ({len(entries)} parameters read)",
            "empty",
            data={"parameters": len(entries)},
        )
