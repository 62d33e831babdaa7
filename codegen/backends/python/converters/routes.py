"""The converters between endpoints: ``convert/<endpoint>.py``, ``convert/<a>_<b>.py`` and the
package's ``__init__.py``.

Each policy of a converter is a chain of mapping functions (:class:`~.mapping_module.Edge`)
found at generation time, the shortest in mapping-name order: strict through the concepts,
px4 and ardupilot through the firmware's own code paths. Nothing is looked up at run time.
"""

from __future__ import annotations

from dataclasses import dataclass

from ....errors import BattgenError
from ....ir import CONCEPTS_ENDPOINT, Endpoint, Schema
from ....ir.mapping_routes import FIRMWARE_POLICIES, POLICIES, route
from .. import naming
from ..literals import docstring, py_literal
from .classes import Import, class_names, import_lines
from .context import INDENT, call
from .mapping_module import Edge

PACKAGE = "convert"
_NO_ROUTE = "no {{policy}} behaviour converts {s} to {t}; use another policy"
# names a converter module binds besides its message classes
_TAKEN = ("BatteryState", "policy", "report")


@dataclass(frozen=True)
class Converter:
    """A generated converter: its module and function, the policies it has, its extra inputs."""

    source: str
    target: str
    module: str
    function: str
    policies: tuple[str, ...]
    inputs: tuple[str, ...]


class Routes:
    """Writes the converter modules of a schema's endpoints from its mapping functions."""

    def __init__(self, schema: Schema, header: str, endpoints: dict[str, Endpoint], edges: list[Edge]) -> None:
        self.schema = schema
        self.header = header
        self.endpoints = endpoints
        self.edges = edges
        self.files: dict[str, str] = {}
        self.converters: list[Converter] = []

    def pair_modules(self) -> dict[str, str]:
        """The endpoint modules (format <-> concepts) and the pair modules; returns every file so far."""
        names = list(self.endpoints)
        for ep in names:  # format <-> concepts
            directions = [("to_concepts", ep, CONCEPTS_ENDPOINT), ("from_concepts", CONCEPTS_ENDPOINT, ep)]
            self.module(ep, f"Converters between {ep} and the shared concepts.", directions)
        for i, a in enumerate(names):
            for b in names[i + 1 :]:
                module = f"{a}_{b}"
                if module in self.endpoints:
                    raise BattgenError(f"converter module {module} would clash with the endpoint of that name")
                directions = [(f"{s}_to_{t}", s, t) for s, t in ((a, b), (b, a))]
                self.module(module, f"Converters between {a} and {b}.", directions)
        return self.files

    def module(self, module: str, doc: str, directions: list[tuple[str, str, str]]) -> None:
        """Write ``module`` with a function per (name, source, target) that has a route."""
        sides = [ep for _, s, t in directions for ep in (s, t) if ep != CONCEPTS_ENDPOINT]
        messages = [q for ep in dict.fromkeys(sides) for q in self.endpoints[ep].messages]
        classes, names = class_names(self.schema, messages, _TAKEN)
        functions: list[str] = []
        used: set[Import] = {(".", "_runtime", "_r")}
        for fname, s, t in directions:
            routes = {p: route(self.edges, s, t, p) for p in POLICIES}
            if all(r is None for r in routes.values()):
                continue
            text, annotations = self.function(fname, s, t, routes, classes)
            functions.append(text)
            used |= {(".", e.module, None) for r in routes.values() if r for e in r}
            used |= {imp for imp in names if (imp[2] or imp[1]) in annotations}
            if CONCEPTS_ENDPOINT in (s, t):
                used.add(("._concepts", "BatteryState", None))
            inputs = tuple(sorted({n for r in routes.values() if r for n in r[0].inputs}))
            policies = tuple(p for p, r in routes.items() if r is not None)
            self.converters.append(Converter(s, t, module, fname, policies, inputs))
        if not functions:
            return
        head = [self.header, docstring(doc, ""), "", "from __future__ import annotations", "", *import_lines(used)]
        text = "\n".join([*head, "", "", ""]) + "\n\n\n".join(functions) + "\n"
        self.files[f"{PACKAGE}/{module}.py"] = text

    def function(
        self, fname: str, source: str, target: str, routes: dict[str, list[Edge] | None], classes: dict[str, str]
    ) -> tuple[str, set[str]]:
        """The converter function's text, and the classes its annotations name."""

        def types(ep: str) -> list[str]:
            return ["BatteryState"] if ep == CONCEPTS_ENDPOINT else [classes[q] for q in self.endpoints[ep].messages]

        src_t, dst_t = types(source), types(target)
        if source == CONCEPTS_ENDPOINT:
            args = ["state"]
        else:
            args = [naming.identifier(a) for a in self.endpoints[source].aliases]
        inputs = sorted({n for r in routes.values() if r for n in r[0].inputs})
        params = [f"{args[0]}: {src_t[0]}"]
        params += [f"{a}: {t} | None = None" for a, t in zip(args[1:], src_t[1:], strict=True)]
        params += ["*", 'policy: str = "strict"', "report: _r.LossReport | None = None"]
        params += [f"{n}: float | None = None" for n in inputs]
        single = len(dst_t) == 1
        returns = dst_t[0] if single else f"tuple[{', '.join(dst_t)}]"
        docs = [f"Convert {source} to {target}.", ""]
        for p, r in routes.items():
            how = " -> ".join(f"{e.mapping.name} ({e.function})" for e in r) if r else "not available"
            docs.append(f"{p}: {how}")
        docs += ["", "Pass a LossReport as report to learn what did not survive."]
        lines = [f"def {fname}({', '.join(params)}) -> {returns}:", docstring("\n".join(docs), INDENT)]
        body: list[str] = []
        for p, r in routes.items():
            if r is not None:
                body.append(f"{INDENT}if policy == {py_literal(p)}:")
                body += self.calls(r, args, inputs, single, p)
        if any("_full" in text for text in body):  # dropped and unknown fields only when the report asks for them
            lines.append(f"{INDENT}_full = report if report is not None and report.full else None")
        lines += body
        missing = tuple(p for p, r in routes.items() if r is None)
        if missing:  # one branch for the policies with no code path between the two
            test = f"policy == {py_literal(missing[0])}" if len(missing) == 1 else f"policy in {py_literal(missing)}"
            no_route = "f" + py_literal(_NO_ROUTE.format(s=source, t=target))
            lines += [f"{INDENT}if {test}:", f"{INDENT * 2}raise _r.ConversionError({no_route})"]
        expected = ", ".join(POLICIES[:-1]) + " or " + POLICIES[-1]
        lines.append(f'{INDENT}raise _r.ConversionError(f"unknown policy {{policy!r}} (expected {expected})")')
        return "\n".join(lines), {*src_t, *dst_t}

    def calls(self, path: list[Edge], args: list[str], inputs: list[str], single: bool, policy: str) -> list[str]:
        """The chain of mapping calls of one policy; a loss is reported where it happens."""
        out = []
        after_firmware = False
        result = ""
        for i, e in enumerate(path):
            first, last = i == 0, i == len(path) - 1
            rep_d = "_full" if first or e.source == CONCEPTS_ENDPOINT or not after_firmware else "None"
            rep_u = "_full" if last else "None"
            given = [*args] if first else [f"*{result}"]
            given += ["rep=report", f"rep_d={rep_d}", f"rep_u={rep_u}"]
            given += [f"{n}={n}" for n in e.inputs if n in inputs] if first else []
            result = f"_{naming.identifier(policy)}_{i + 1}"
            out.append(f"{INDENT * 2}{result} = {call(f'{e.module}.{e.function}', given)}")
            after_firmware = after_firmware or e.mapping.policy in FIRMWARE_POLICIES
        out.append(f"{INDENT * 2}return {result}[0]" if single else f"{INDENT * 2}return {result}")
        return out

    def init_module(self) -> str:
        """The package face: every converter, endpoint and policy, after :meth:`pair_modules`."""
        classes, names = class_names(
            self.schema, [q for ep in self.endpoints.values() for q in ep.messages], ("BatteryState",)
        )
        used: set[Import] = {(".", c.module, None) for c in self.converters} | names
        used |= {("._concepts", "BatteryState", None)}
        used |= {("._runtime", n, None) for n in ("ConversionError", "LossEntry", "LossReport")}

        def objects(pairs: list[str]) -> str:
            return f"({pairs[0]},)" if len(pairs) == 1 else f"({', '.join(pairs)})"

        endpoint_items = [
            f"{py_literal(name)}: "
            + objects([f"({py_literal(a)}, {classes[q]})" for a, q in zip(ep.aliases, ep.messages, strict=True)])
            for name, ep in self.endpoints.items()
        ]
        state = f"({py_literal('state')}, BatteryState)"
        endpoint_items.append(f"{py_literal(CONCEPTS_ENDPOINT)}: {objects([state])}")
        pairs = [(py_literal((c.source, c.target)), c) for c in self.converters]
        exported = ["CONVERTERS", "ENDPOINTS", "INPUTS", "POLICIES", "BatteryState", "ConversionError"]
        exported += ["LossEntry", "LossReport", "converter"]
        lines = [
            self.header,
            docstring(
                "Converters between the battery formats, generated from schemas/mappings/.\n\n"
                "One import per pair, e.g. ``from generated.convert.dronecan_uorb import dronecan_to_uorb``;\n"
                "``CONVERTERS[(source, target)]`` holds every converter, ``ENDPOINTS`` the message classes\n"
                "of each side.",
                "",
            ),
            "",
            "from __future__ import annotations",
            "",
            "from collections.abc import Callable",
            "from typing import Any",
            "",
            *import_lines(used),
            "",
            f"__all__ = {py_literal(exported)}",
            "",
            "# each endpoint's objects in order: the first required, the rest optional companions",
            "ENDPOINTS: dict[str, tuple[tuple[str, type[Any]], ...]] = {" + ", ".join(endpoint_items) + "}",
            "",
            "CONVERTERS: dict[tuple[str, str], Callable[..., Any]] = {"
            + ", ".join(f"{k}: {c.module}.{c.function}" for k, c in pairs)
            + "}",
            "",
            "# the policies each converter supports, and the extra keyword inputs it accepts",
            "POLICIES: dict[tuple[str, str], tuple[str, ...]] = {"
            + ", ".join(f"{k}: {py_literal(c.policies)}" for k, c in pairs)
            + "}",
            "INPUTS: dict[tuple[str, str], tuple[str, ...]] = {"
            + ", ".join(f"{k}: {py_literal(c.inputs)}" for k, c in pairs if c.inputs)
            + "}",
            "",
            "",
            "def converter(source: str, target: str) -> Callable[..., Any]:",
            '    """The converter from ``source`` to ``target`` (endpoint names), or ConversionError."""',
            "    found = CONVERTERS.get((source, target))",
            "    if found is None:",
            '        pairs = ", ".join(f"{s}->{t}" for s, t in sorted(CONVERTERS))',
            '        raise ConversionError(f"no converter from {source!r} to {target!r} (known: {pairs})")',
            "    return found",
        ]
        return "\n".join(lines) + "\n"
