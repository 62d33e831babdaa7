"""Parameter files (.param / .parm / .params) as records.

One record per parameter set: the whole of an ArduPilot .param file, one per (vehicle, component)
of a QGroundControl .params file. A record holds the parameters the message models (a full dump's
other parameters are dropped, see :func:`codegen.inputs.parameters.files.select`) and, as its
``context``, the whole set (the failsafe checks read every battery's BATT*_ group and the
parameters that tell the vehicle); sets holding none of them are skipped, with one notice when the
whole file holds none. A violation points at its parameter's line (any parameter of the set). A
parameter written twice is one warning notice; its last value counts.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ..model import MessageClass, field_names
from ..records import Item, Notice, Record, first_field_locator
from . import files as parameter_files


def read_parameter_records(path: Path, name: str, model: MessageClass) -> Iterator[Item]:
    """The parameter sets of one file (ParameterFileError names file and line when it is malformed)."""
    entries = parameter_files.load(path, name)  # read eagerly: a malformed file fails before any record
    return _records(entries, name, model.QUALIFIED_NAME, field_names(model))


def _records(entries: list[parameter_files.ParamEntry], name: str, qualified: str, names: set[str]) -> Iterator[Item]:
    for repeat in parameter_files.repeats(entries):
        data = {"parameter": repeat.name, "lines": list(repeat.lines), "values": list(repeat.values)}
        yield Notice(name, f"line {repeat.lines[-1]}: {repeat.message()}", "repeated", data=data)
    index = 0
    for (vehicle, component), group in parameter_files.sets(entries).items():
        chosen = [e for e in group if e.name in names]
        if not chosen:
            continue  # e.g. a gimbal's parameters in a QGC file: nothing of this message
        qgc = vehicle is not None
        yield Record(
            index,
            chosen[0].line,
            {e.name: e.value for e in chosen},
            name,
            where=f"vehicle {vehicle} component {component}" if qgc else "",
            locate=first_field_locator({e.name: e.line for e in group}),
            location={"vehicle": vehicle, "component": component} if qgc else None,
            context={e.name: e.value for e in group},
        )
        index += 1
    if index == 0:
        yield Notice(
            name,
            f"no parameter of {qualified} in this file ({len(entries)} parameters read)",
            "empty",
            data={"parameters": len(entries)},
        )
