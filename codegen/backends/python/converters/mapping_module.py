"""``convert/_map_<mapping>.py``: one function per direction of a mapping (``forward``, ``backward``)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ....ir import CONCEPTS_ENDPOINT, Concept, Endpoint, Mapping, Schema
from .. import naming
from ..literals import docstring
from .classes import class_names, import_lines
from .context import INDENT, ModuleConstants, Side
from .function import FunctionBuilder

# a call into the array algorithms module, not an endpoint alias ending in "cells" (s_cells.voltages)
_USES_CELLS = re.compile(r"(?<![\w.])_cells\.")
_USES_ARDUPILOT = re.compile(r"(?<![\w.])_ap\.")

# names a mapping module binds besides its message classes
_TAKEN = ("BatteryState", "forward", "backward", "_math")
_USES_MATH = re.compile(r"(?<![\w.])_math\.")


@dataclass(frozen=True)
class Edge:
    """One function of a mapping module, an edge of the graph of conversions: what it converts, and
    what it takes besides the objects."""

    source: str
    target: str
    module: str  # _map_<name>
    function: str  # forward / backward
    mapping: Mapping
    inputs: tuple[str, ...]


def _side(schema: Schema, endpoints: dict[str, Endpoint], name: str, prefix: str) -> Side:
    if name == CONCEPTS_ENDPOINT:
        return Side(None, [], [prefix], [CONCEPTS_ENDPOINT])
    ep = endpoints[name]
    return Side(
        ep,
        [schema.message(q) for q in ep.messages],
        [f"{prefix}_{naming.identifier(a)}" for a in ep.aliases],
        list(ep.aliases),
    )


def mapping_module(
    schema: Schema, header: str, mapping: Mapping, concepts: dict[str, Concept], endpoints: dict[str, Endpoint]
) -> tuple[str, str, list[Edge]]:
    """(module name, text, the functions it holds)."""
    module = f"_map_{naming.identifier(mapping.name)}"
    messages = [q for e in (mapping.source, mapping.target) if e != CONCEPTS_ENDPOINT for q in endpoints[e].messages]
    classes, class_imports = class_names(schema, messages, _TAKEN)
    constants = ModuleConstants()
    functions: list[list[str]] = []
    made: list[Edge] = []
    directions = [("forward", False)] + ([("backward", True)] if mapping.reversible else [])
    for fname, backward in directions:
        src_name, dst_name = (mapping.target, mapping.source) if backward else (mapping.source, mapping.target)
        builder = FunctionBuilder(
            schema,
            mapping,
            concepts,
            _side(schema, endpoints, src_name, "s"),
            _side(schema, endpoints, dst_name, "t"),
            fname,
            classes,
            constants,
        )
        functions.append(_function(builder, src_name, dst_name, builder.build()))
        made.append(Edge(src_name, dst_name, module, fname, mapping, tuple(builder.inputs)))
    where = f" ({mapping.location})" if mapping.location else ""
    doc = docstring(f"Mapping {mapping.name}{where}, policy {mapping.policy}.\n\n{mapping.doc}", "")
    consts = list(constants.lines.values())
    code = [line for lines in functions for line in lines] + consts
    names = set(class_imports) | {(".", "_runtime", "_r")}
    if any(_USES_CELLS.search(line) for line in code if not line.lstrip().startswith("#")):
        names.add((".", "_cells", None))  # the array algorithms (runtime/convert/_cells.py)
    if any(_USES_ARDUPILOT.search(line) for line in code if not line.lstrip().startswith("#")):
        names.add((".", "_ardupilot", "_ap"))  # ArduPilot's battery arithmetic (runtime/convert/_ardupilot.py)
    if CONCEPTS_ENDPOINT in (mapping.source, mapping.target):
        names.add(("._concepts", "BatteryState", None))
    head = [header, doc, "", "from __future__ import annotations", ""]
    if any(_USES_MATH.search(line) for line in code if not line.lstrip().startswith("#")):
        head += ["import math as _math", ""]  # private, like every module the generated code uses
    head += import_lines(names)
    text = "\n".join([*head, *(["", *consts] if consts else [])]) + "\n\n\n"
    text += "\n\n\n".join("\n".join(f) for f in functions)
    return module, text + "\n", made


def _function(b: FunctionBuilder, src: str, dst: str, body: list[str]) -> list[str]:
    def annotations(side: Side) -> list[str]:
        if side.endpoint is None:
            return ["BatteryState"]
        return [b.classes[q] for q in side.endpoint.messages]

    src_t, dst_t = annotations(b.src), annotations(b.dst)
    params = [f"{b.src.names[0]}: {src_t[0]}"]
    params += [f"{n}: {t} | None = None" for n, t in zip(b.src.names[1:], src_t[1:], strict=True)]
    report = "_r.LossReport | None = None"
    params += ["*", f"rep: {report}", f"rep_d: {report}", f"rep_u: {report}"]
    params += [f"{name}: float | None = None" for name in b.inputs]
    lines = [f"def {b.direction}({', '.join(params)}) -> tuple[{', '.join(dst_t)}]:"]
    lines.append(docstring(f"{src} -> {dst}: returns the target objects as a tuple.", INDENT))
    if b.dst.endpoint is None:
        lines.append(f"{INDENT}{b.dst.names[0]} = BatteryState()")
    else:
        lines += [
            f"{INDENT}{var} = {b.classes[q]}()" for q, var in zip(b.dst.endpoint.messages, b.dst.names, strict=True)
        ]
    returned = f"({b.dst.names[0]},)" if len(b.dst.names) == 1 else f"({', '.join(b.dst.names)})"
    return [*lines, *body, "", f"{INDENT}return {returned}"]
