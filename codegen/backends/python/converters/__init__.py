"""Converter generator: the IR's mappings become ``generated/convert/``, plain Python functions.

Layout of the generated package:

- ``convert/_runtime.py``  the loss report and numeric helpers (copied from ``runtime/convert/_runtime.py``)
- ``convert/_concepts.py`` ``BatteryState``: the shared concepts as a dataclass (SI units, None = unknown)
- ``convert/_map_<mapping>.py`` one function per direction of each mapping (``forward``/``backward``)
- ``convert/<endpoint>.py``  ``to_concepts`` / ``from_concepts`` for each format with a concept mapping
- ``convert/<a>_<b>.py``  ``a_to_b`` / ``b_to_a`` for every pair: each policy is a chain of
  mapping functions found at generation time (strict through the concepts, px4 through PX4's
  own code paths); nothing is interpreted at run time.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping as _Map
from dataclasses import dataclass

from ....errors import BattgenError
from ....ir import CONCEPTS_ENDPOINT, Concept, Endpoint, Mapping, Message, Schema
from .. import naming
from ..extensions import Contribution
from ..literals import docstring, py_literal
from ..runtime import copied
from ..views import ClassView, ModuleContext
from .emit import FunctionBuilder, Side

PACKAGE = "convert"
POLICIES = ("strict", "px4")
_NO_ROUTE = "no {p} behaviour converts {s} to {t}; use another policy"

_KIND_TYPES = {
    "number": "float | None",
    "integer": "int | None",
    "bool": "bool | None",
    "text": "str | None",
    "list": "tuple[float, ...] | None",
    "choice": "str | None",
    "flags": "tuple[str, ...] | None",
}


@dataclass(frozen=True)
class Edge:
    source: str
    target: str
    policies: frozenset[str]
    module: str  # _map_<name>
    function: str  # forward / backward
    mapping: Mapping
    inputs: tuple[str, ...]


def _mappings(schema: Schema) -> list[Mapping]:
    return [m for s in schema.mappings for m in s.mappings]


def _concepts(schema: Schema) -> dict[str, Concept]:
    return {c.name: c for s in schema.mappings for c in s.concepts}


def _endpoints(schema: Schema) -> dict[str, Endpoint]:
    return {e.name: e for s in schema.mappings for e in s.endpoints}


def _class_import(msg: Message, alias: str) -> str:
    return f"from ..{naming.module_path(msg)} import {naming.class_name(msg)} as {alias}"


class _Generator:
    def __init__(self, schema: Schema, header: str) -> None:
        self.schema = schema
        self.header = header
        self.concepts = _concepts(schema)
        self.endpoints = _endpoints(schema)
        self.edges: list[Edge] = []
        self.files: dict[str, str] = {}

    # -- per mapping -----------------------------------------------------------------------

    def side(self, name: str, prefix: str) -> Side:
        if name == CONCEPTS_ENDPOINT:
            return Side(None, [], [prefix])
        ep = self.endpoints[name]
        return Side(
            ep,
            [self.schema.message(q) for q in ep.messages],
            [f"{prefix}_{naming.identifier(a)}" for a in ep.aliases],
        )

    def mapping_module(self, mapping: Mapping) -> None:
        module = f"_map_{naming.identifier(mapping.name)}"
        classes: dict[str, str] = {}
        for ep_name in (mapping.source, mapping.target):
            if ep_name != CONCEPTS_ENDPOINT:
                for q in self.endpoints[ep_name].messages:
                    classes.setdefault(q, f"_C{len(classes)}")
        functions: list[str] = []
        consts: list[str] = []
        policies = frozenset(POLICIES) if mapping.policy == "any" else frozenset({mapping.policy})
        directions = [("forward", False)] + ([("backward", True)] if mapping.reversible else [])
        for fname, backward in directions:
            src_name, dst_name = (mapping.target, mapping.source) if backward else (mapping.source, mapping.target)
            builder = FunctionBuilder(
                schema=self.schema,
                mapping=mapping,
                concepts=self.concepts,
                src=self.side(src_name, "s"),
                dst=self.side(dst_name, "t"),
                name=fname,
                backward=backward,
                classes=classes,
            )
            body = builder.build()
            consts.extend(builder.module_consts)
            functions.append(self.function_text(builder, fname, src_name, dst_name, body))
            self.edges.append(Edge(src_name, dst_name, policies, module, fname, mapping, tuple(builder.inputs)))
        loc = f" ({mapping.location})" if mapping.location else ""
        doc = docstring(f"Mapping {mapping.name}{loc}, policy {mapping.policy}.\n\n{mapping.doc}", "")
        imports = ["import math", "", "from . import _runtime as _r", "from ._concepts import BatteryState"]
        imports += [_class_import(self.schema.message(q), a) for q, a in classes.items()]
        text = "\n".join(
            [self.header, doc, "", "from __future__ import annotations", "", *imports, "", "", *consts, "", "", ""]
        )
        text += "\n\n\n".join(functions) + "\n"
        self.files[f"{PACKAGE}/{module}.py"] = _tidy(text)

    def function_text(self, b: FunctionBuilder, fname: str, src: str, dst: str, body: list[str]) -> str:
        def ann(side: Side) -> list[str]:
            if side.endpoint is None:
                return ["BatteryState"]
            return [b.classes[q] for q in side.endpoint.messages]

        src_t, dst_t = ann(b.src), ann(b.dst)
        params = [f"{b.src.names[0]}: {src_t[0]}"]
        params += [f"{n}: {t} | None = None" for n, t in zip(b.src.names[1:], src_t[1:], strict=True)]
        rep = "_r.LossReport | None = None"
        kw = [f"rep: {rep}", f"rep_d: {rep}", f"rep_u: {rep}", *(f"{i}: float | None = None" for i in b.inputs)]
        head = f"def {fname}({', '.join(params)}, *, {', '.join(kw)}) -> tuple[{', '.join(dst_t)}]:"
        doc = docstring(f"{src} -> {dst}: returns the target objects as a tuple.", "    ")
        if b.dst.endpoint is None:
            make = [f"    {b.dst.names[0]} = BatteryState()"]
        else:
            make = [
                f"    {var} = {b.classes[q]}()" for q, var in zip(b.dst.endpoint.messages, b.dst.names, strict=True)
            ]
        ret = f"    return ({', '.join(b.dst.names)},)"
        return "\n".join([head, doc, *make, *body, ret])

    def side_types(self, name: str, imports: set[str]) -> list[str]:
        """Annotations for an endpoint's objects, registering the imports they need."""
        if name == CONCEPTS_ENDPOINT:
            imports.add("from ._concepts import BatteryState")
            return ["BatteryState"]
        out = []
        for q in self.endpoints[name].messages:
            alias = "_T_" + naming.identifier(q.replace(".", "_"))
            imports.add(_class_import(self.schema.message(q), alias))
            out.append(alias)
        return out

    # -- concepts --------------------------------------------------------------------------

    def concepts_module(self) -> None:
        units_of = {c.name: c.unit.symbol if c.unit else None for c in self.concepts.values()}
        choices_of = {c.name: c.choices for c in self.concepts.values() if c.choices}
        lines = [
            self.header,
            docstring(
                "The shared battery state every format converts to and from: SI units, None for unknown.\n\n"
                "The battery failsafe evaluates battery data from any format through it.",
                "",
            ),
            "",
            "from __future__ import annotations",
            "",
            "import dataclasses",
            "import math",
            "from collections.abc import Mapping",
            "from typing import Any, ClassVar",
            "",
            "from . import _runtime as _r",
            "",
            "",
            "@dataclasses.dataclass(slots=True)",
            "class BatteryState:",
            docstring("One battery's state in the shared concepts (see schemas/mappings/concepts.yaml).", "    "),
            "",
            f"    UNITS: ClassVar[dict[str, str | None]] = {_dict_literal(units_of)}",
            f"    KINDS: ClassVar[dict[str, str]] = {_dict_literal({c.name: c.kind for c in self.concepts.values()})}",
            f"    CHOICES: ClassVar[dict[str, tuple[str, ...]]] = {_dict_literal(choices_of)}",
            "",
        ]
        for c in self.concepts.values():
            unit = f" [{c.unit.symbol}]" if c.unit else ""
            lines.append(f"    {naming.identifier(c.name)}: {_KIND_TYPES[c.kind]} = None")
            lines.append(docstring(f"{c.doc}{unit}", "    "))
        lines += [
            "",
            "    def to_dict(self) -> dict[str, Any]:",
            '        """Plain data keyed by concept name (lists for cells and flags, None for unknown)."""',
            "        out: dict[str, Any] = {}",
            "        for name in self.KINDS:",
            "            value = getattr(self, name)",
            "            out[name] = list(value) if isinstance(value, tuple) else value",
            "        return out",
            "",
            "    @classmethod",
            "    def from_dict(cls, data: Mapping[str, Any]) -> BatteryState:",
            '        """Build from plain data; unknown keys and ill-typed values raise ConversionError."""',
            "        obj = cls()",
            "        for name, value in data.items():",
            "            kind = cls.KINDS.get(name)",
            "            if kind is None:",
            "                raise _r.ConversionError(f'{name}: not a battery concept')",
            "            choices = cls.CHOICES.get(name, ())",
            "            setattr(obj, name, None if value is None else _coerce(name, kind, value, choices))",
            "        return obj",
            "",
            "",
            "def _coerce(name: str, kind: str, value: Any, choices: tuple[str, ...]) -> Any:",
            "    if kind == 'number' and isinstance(value, int | float) and not isinstance(value, bool):",
            "        return float(value)",
            "    if kind == 'number' and value in ('NaN', 'nan'):",
            "        return math.nan",
            "    if kind == 'integer' and isinstance(value, int) and not isinstance(value, bool):",
            "        return value",
            "    if kind == 'bool' and isinstance(value, bool):",
            "        return value",
            "    if kind == 'text' and isinstance(value, str):",
            "        return value",
            "    if kind == 'choice' and value in choices:",
            "        return value",
            "    if kind == 'list' and isinstance(value, list | tuple):",
            "        return tuple(_coerce(name, 'number', v, ()) for v in value)",
            "    if kind == 'flags' and isinstance(value, list | tuple) and all(v in choices for v in value):",
            "        return tuple(c for c in choices if c in value)",
            "    raise _r.ConversionError(f'{name}: expected a {kind} value, got {value!r}')",
        ]
        self.files[f"{PACKAGE}/_concepts.py"] = _tidy("\n".join(lines) + "\n")

    # -- paths and pairs -------------------------------------------------------------------

    def path(self, source: str, target: str, policy: str) -> list[Edge] | None:
        edges = sorted((e for e in self.edges if policy in e.policies), key=lambda e: (e.mapping.name, e.function))
        queue: deque[tuple[str, list[Edge]]] = deque([(source, [])])
        seen = {source}
        while queue:
            node, route = queue.popleft()
            if node == target:
                return route
            for e in edges:
                if e.source == node and e.target not in seen:
                    seen.add(e.target)
                    queue.append((e.target, [*route, e]))
        return None

    def endpoint_names(self) -> list[str]:
        return list(self.endpoints)

    def call_lines(
        self, route: list[Edge], arg_names: list[str], inputs: list[str], single: bool, policy: str
    ) -> list[str]:
        out = []
        args = ", ".join(arg_names)
        after_px4 = False
        for i, e in enumerate(route):
            first, last = i == 0, i == len(route) - 1
            rep_d = "report" if first or e.source == CONCEPTS_ENDPOINT or not after_px4 else "None"
            rep_u = "report" if last else "None"
            extra = "".join(f", {n}={n}" for n in e.inputs if n in inputs) if first else ""
            call_args = args if first else f"*_{policy}{i}"
            call = f"{e.module}.{e.function}({call_args}, rep=report, rep_d={rep_d}, rep_u={rep_u}{extra})"
            out.append(f"_{policy}{i + 1} = {call}")
            after_px4 = after_px4 or e.mapping.policy == "px4"
        out.append(f"return _{policy}{len(route)}[0]" if single else f"return _{policy}{len(route)}")
        return out

    def converter_function(
        self, fname: str, source: str, target: str
    ) -> tuple[str, set[str], list[str], tuple[str, ...], set[str]] | None:
        routes = {p: self.path(source, target, p) for p in POLICIES}
        if all(r is None for r in routes.values()):
            return None
        imports: set[str] = set()
        src_t = self.side_types(source, imports)
        dst_t = self.side_types(target, imports)
        arg_names = (
            ["state"] if source == CONCEPTS_ENDPOINT else [naming.identifier(a) for a in self.endpoints[source].aliases]
        )
        inputs = sorted({n for r in routes.values() if r for n in r[0].inputs})
        params = [f"{arg_names[0]}: {src_t[0]}"]
        params += [f"{a}: {t} | None = None" for a, t in zip(arg_names[1:], src_t[1:], strict=True)]
        kw = [
            "policy: str = 'strict'",
            "report: _r.LossReport | None = None",
            *(f"{n}: float | None = None" for n in inputs),
        ]
        modules = {e.module for r in routes.values() if r for e in r}
        single = len(dst_t) == 1
        ret = dst_t[0] if single else f"tuple[{', '.join(dst_t)}]"
        docs = [f"Convert {source} to {target}."]
        for p, r in routes.items():
            how = " -> ".join(f"{e.mapping.name} ({e.function})" for e in r) if r else "not available"
            docs.append(f"{p}: {how}")
        docs.append("Pass a LossReport as report to learn what did not survive.")
        lines = [f"def {fname}({', '.join(params)}, *, {', '.join(kw)}) -> {ret}:", docstring("\n".join(docs), "    ")]
        for p, r in routes.items():
            lines.append(f"    if policy == {py_literal(p)}:")
            if r is None:
                message = py_literal(_NO_ROUTE.format(p=p, s=source, t=target))
                lines.append(f"        raise _r.ConversionError({message})")
            else:
                lines.extend("        " + x for x in self.call_lines(r, arg_names, inputs, single, p))
        lines.append(
            "    raise _r.ConversionError('unknown policy %r (expected %s)' % (policy, "
            + py_literal(" or ".join(POLICIES))
            + "))"
        )
        return "\n".join(lines), modules, [p for p, r in routes.items() if r is not None], tuple(inputs), imports

    def pair_modules(self) -> list[tuple[str, str, str, str, list[str], tuple[str, ...]]]:
        """Writes the pair and endpoint modules; returns (source, target, module, function, policies, inputs)."""
        registry: list[tuple[str, str, str, str, list[str], tuple[str, ...]]] = []
        names = self.endpoint_names()
        for ep in names:  # format <-> concepts
            directions = [("to_concepts", ep, CONCEPTS_ENDPOINT), ("from_concepts", CONCEPTS_ENDPOINT, ep)]
            self.direction_module(ep, f"Converters between {ep} and the shared concepts.", directions, registry)
        for i, a in enumerate(names):
            for b in names[i + 1 :]:
                module = f"{a}_{b}"
                if module in self.endpoints:
                    raise BattgenError(f"converter module {module} would clash with the endpoint of that name")
                directions = [(f"{s}_to_{t}", s, t) for s, t in ((a, b), (b, a))]
                self.direction_module(module, f"Converters between {a} and {b}.", directions, registry)
        return registry

    def direction_module(
        self,
        module: str,
        doc: str,
        directions: list[tuple[str, str, str]],
        registry: list[tuple[str, str, str, str, list[str], tuple[str, ...]]],
    ) -> None:
        """Write ``module`` with a function per (name, source, target) that has a route; record them."""
        funcs: list[str] = []
        modules: set[str] = set()
        imports: set[str] = set()
        for fname, s, t in directions:
            built = self.converter_function(fname, s, t)
            if built is None:
                continue
            text, mods, pols, inputs, imps = built
            funcs.append(text)
            modules |= mods
            imports |= imps
            registry.append((s, t, module, fname, pols, inputs))
        if funcs:
            self.write_module(module, doc, funcs, modules, imports)

    def write_module(self, module: str, doc: str, funcs: list[str], modules: set[str], types: set[str]) -> None:
        imports = ["from . import _runtime as _r"] + [f"from . import {m}" for m in sorted(modules)] + sorted(types)
        text = "\n".join(
            [self.header, docstring(doc, ""), "", "from __future__ import annotations", "", *imports, "", "", ""]
        )
        self.files[f"{PACKAGE}/{module}.py"] = _tidy(text + "\n\n\n".join(funcs) + "\n")

    def init_module(self, registry: list[tuple[str, str, str, str, list[str], tuple[str, ...]]]) -> None:
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
            "from . import " + ", ".join(sorted({r[2] for r in registry})),
            "from ._concepts import BatteryState",
            "from ._runtime import ConversionError, LossEntry, LossReport",
        ]
        classes: list[str] = []
        ep_lines = []
        for name, ep in self.endpoints.items():
            items = []
            for alias, q in zip(ep.aliases, ep.messages, strict=True):
                cls = f"_E{len(classes)}"
                classes.append(_class_import(self.schema.message(q), cls))
                items.append(f"({py_literal(alias)}, {cls})")
            ep_lines.append(f"    {py_literal(name)}: ({', '.join(items)},),")
        lines += classes
        lines += [
            "",
            "__all__ = [",
            "    'CONVERTERS', 'ENDPOINTS', 'INPUTS', 'POLICIES',",
            "    'BatteryState', 'ConversionError', 'LossEntry', 'LossReport', 'converter',",
            "]",
            "",
            "# each endpoint's objects in order: the first required, the rest optional companions",
            "ENDPOINTS: dict[str, tuple[tuple[str, type[Any]], ...]] = {",
            *ep_lines,
            f"    {py_literal(CONCEPTS_ENDPOINT)}: (('state', BatteryState),),",
            "}",
            "",
            "CONVERTERS: dict[tuple[str, str], Callable[..., Any]] = {",
            *(f"    ({py_literal(s)}, {py_literal(t)}): {m}.{f}," for s, t, m, f, _, _ in registry),
            "}",
            "",
            "# the policies each converter supports, and the extra keyword inputs it accepts",
            "POLICIES: dict[tuple[str, str], tuple[str, ...]] = {",
            *(f"    ({py_literal(s)}, {py_literal(t)}): {py_literal(tuple(p))}," for s, t, _, _, p, _ in registry),
            "}",
            "INPUTS: dict[tuple[str, str], tuple[str, ...]] = {",
            *(f"    ({py_literal(s)}, {py_literal(t)}): {py_literal(i)}," for s, t, _, _, _, i in registry if i),
            "}",
            "",
            "",
            "def converter(source: str, target: str) -> Callable[..., Any]:",
            '    """The converter from ``source`` to ``target`` (endpoint names), or ConversionError."""',
            "    found = CONVERTERS.get((source, target))",
            "    if found is None:",
            "        pairs = ', '.join(f'{s}->{t}' for s, t in sorted(CONVERTERS))",
            "        raise ConversionError(f'no converter from {source!r} to {target!r} (known: {pairs})')",
            "    return found",
        ]
        self.files[f"{PACKAGE}/__init__.py"] = _tidy("\n".join(lines) + "\n")

    def render(self) -> dict[str, str]:
        self.files.update(copied(f"{PACKAGE}/_runtime.py"))
        self.concepts_module()
        for mapping in _mappings(self.schema):
            self.mapping_module(mapping)
        registry = self.pair_modules()
        self.init_module(registry)
        return self.files


def _dict_literal(data: _Map[str, object]) -> str:
    return "{" + ", ".join(f"{py_literal(k)}: {py_literal(v)}" for k, v in data.items()) + "}"


def _tidy(text: str) -> str:
    """Collapse runs of blank lines to at most two, strip trailing spaces."""
    out: list[str] = []
    blanks = 0
    for line in text.split("\n"):
        line = line.rstrip()
        blanks = blanks + 1 if not line else 0
        if blanks <= 2:
            out.append(line)
    return "\n".join(out).rstrip("\n") + "\n"


class _Converters:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        return Contribution()

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        if not any(s.mappings for s in schema.mappings):
            return {}
        return _Generator(schema, header).render()


EXTENSION = _Converters()
