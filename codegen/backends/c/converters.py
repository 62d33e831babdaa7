"""The converters as C, generated from the mappings rule by rule as the Python backend writes
``generated/convert/``: each direction of a mapping is a static function (``map_<mapping>_<direction>``,
its sides an endpoint's messages or the concepts, ``battgen_concepts``), and each converter between
two formats of the C library, per policy, is a public function chaining them along the route the
Python converter takes (``battgen_convert_<source>_to_<target>_<policy>``): strict through the
concepts, px4 through PX4's own code paths. The same arithmetic (px4: float32 as PX4's C does,
float16 rounded to nearest even as received; strict: double, as Python computes), the same C integer
conversions, the same loss report entries (kind and field; the Python report's detail text is not kept).

A mapping holding an op not written in C yet raises :class:`Unsupported`; a converter needing it is
left out, and :func:`c_converters` says which (the README lists them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Concept,
    Direction,
    Field,
    Mapping,
    PrimitiveKind,
    Rule,
    Schema,
    SourceFormat,
)
from ...ir.mapping_routes import FIRMWARE_POLICIES, POLICIES, route
from ...ir.mapping_visitor import visit
from .convert_concept_cells import ConceptCellOps
from .convert_concepts import STATE
from .convert_px4 import PX4Ops
from .convert_px4_cells import PX4CellOps
from .convert_values import Unsupported, c_type, defaults, differs, literal, primitive
from .types import ident

_FORMATS = (SourceFormat.DRONECAN, SourceFormat.MAVLINK, SourceFormat.UORB)


@dataclass(frozen=True)
class Edge:
    """One direction of one mapping (a :class:`~codegen.ir.mapping_routes.MappingEdge`)."""

    source: str
    target: str
    function: str
    mapping: Mapping


@dataclass(frozen=True)
class MapFunction:
    """One direction of one mapping as a static C function."""

    edge: Edge
    name: str
    params: list[str]  # C parameter declarations, reports last
    body: list[str]
    inputs: list[str]
    targets: list[str]  # the qualified messages it writes (none: the concepts)


@dataclass(frozen=True)
class CConverter:
    """A public converter: source side -> target side under one policy, a chain of map functions."""

    source: str
    target: str
    policy: str
    name: str
    sources: list[tuple[str, str, bool]]  # (qualified, parameter, optional)
    targets: list[tuple[str, str]]  # (qualified, parameter)
    inputs: list[str]
    chain: list[MapFunction]

    def prototype(self) -> str:
        params = [f"const {c_type(q)} *{v}" for q, v, _ in self.sources]
        params += [f"const float *{name}" for name in self.inputs]
        params += [f"{c_type(q)} *{v}" for q, v in self.targets]
        params.append("battgen_loss_report *rep")
        return f"void {self.name}({', '.join(params)})"

    def body(self) -> list[str]:
        """The calls along the route; a loss reported where it happens, as the Python converter does."""
        out: list[str] = []
        between: list[list[str]] = []  # each intermediate stage's objects
        for i, f in enumerate(self.chain[:-1], 1):
            if not f.targets:
                out.append(f"{STATE} c{i};")
                between.append([f"&c{i}"])
            else:
                out += [f"{c_type(q)} c{i}_{k};" for k, q in enumerate(f.targets)]
                between.append([f"&c{i}_{k}" for k in range(len(f.targets))])
        after_firmware = False
        for i, f in enumerate(self.chain):
            first, last = i == 0, i == len(self.chain) - 1
            e = f.edge
            args = [v for _, v, _ in self.sources] if first else list(between[i - 1])
            args += [n if n in self.inputs else "NULL" for n in f.inputs] if first else ["NULL" for _ in f.inputs]
            args += [v for _, v in self.targets] if last else list(between[i])
            rep_d = "rep" if first or e.source == CONCEPTS_ENDPOINT or not after_firmware else "NULL"
            args += ["rep", rep_d, "rep" if last else "NULL"]
            out.append(f"{f.name}({', '.join(args)});")
            after_firmware = after_firmware or e.mapping.policy in FIRMWARE_POLICIES
        return out


class _Builder(PX4Ops, PX4CellOps, ConceptCellOps):
    """One direction of one mapping as C (see the module docstring)."""

    def _unsupported(self, rule: Rule, op: object) -> None:
        raise Unsupported(f"op {rule.op.NAME}")

    visit_dt_pack = visit_ocv_soc = visit_px4_udral_energy = _unsupported
    # ArduPilot's DroneCAN monitor (the ardupilot policy): not written in C yet, so that converter is left out
    visit_ardupilot_temperature = visit_ardupilot_current = _unsupported
    visit_ardupilot_cells = visit_ardupilot_estimates = _unsupported
    visit_value_flags = _unsupported  # one condition of several as flags (UDRAL's error): no C codec for UDRAL yet

    # -- the function ----------------------------------------------------------------------

    def defaults_fn(self, qualified: str) -> str:
        fn = f"defaults_{c_type(qualified)}"
        self.helpers[fn] = [
            f"static void {fn}({c_type(qualified)} *m) {{",
            "battgen_zero(m, sizeof *m);",
            *defaults(self.schema, self.schema.message(qualified), "(*m)"),
            "}",
        ]
        return fn

    def params(self) -> list[str]:
        """The function's parameters: sources, inputs, targets, the three reports (rep_d: dropped,
        rep_u: unknown, as the Python mapping functions take them)."""
        out: list[str] = []
        for side, prefix, const in ((self.src, "s", "const "), (self.dst, "t", "")):
            if side is None:
                out.append(f"{const}{STATE} *{prefix}")
            else:
                out += [f"{const}{c_type(q)} *{self.var(side, q, prefix)}" for q in side.messages]
            if prefix == "s":
                out += [f"const float *{name}" for name in self.inputs]
        return [*out, "battgen_loss_report *rep", "battgen_loss_report *rep_d", "battgen_loss_report *rep_u"]

    def build(self) -> list[str]:
        if self.dst is None:
            self.emit("battgen_zero(t, sizeof *t);")
        else:
            for qualified in self.dst.messages:  # what a fresh Python object holds
                self.emit(f"{self.defaults_fn(qualified)}({self.var(self.dst, qualified, 't')});")
        for rule in self.mapping.rules:
            if rule.only is not None and (rule.only is Direction.BACKWARD) != self.backward:
                continue
            reads = rule.targets if self.backward else rule.sources
            optional = sorted(
                {
                    self.var(self.src, r.message, "s")
                    for r in reads
                    if r.message != CONCEPTS_ENDPOINT and self.optional(r.message)
                }
            )
            where = f"{rule.location}: " if rule.location is not None else ""
            self.emit(f"/* {where}{rule.op.NAME} */")
            start = len(self.lines)
            visit(rule, self)
            block = self.lines[start:]
            del self.lines[start:]
            if optional and not rule.op.HANDLES_MISSING:
                self.emit(f"if ({' && '.join(f'{v} != NULL' for v in optional)}) {{", *block, "}")
            else:
                self.emit("{", *block, "}")
        self.epilogue()
        return self.lines

    def unused(self) -> list[str]:
        """``(void)p;`` for every parameter (an optional message, an input or a report a mapping may not use)."""
        return [f"(void){p.rsplit('*', 1)[1]};" for p in self.params()]

    def epilogue(self) -> None:
        """Source bits and fields nobody read (a field differing from a fresh message's), concepts nobody
        read, target fields no rule wrote, and between formats those left at their "unknown" marker:
        as the Python mapping function reports them."""
        self.emit("/* what did not survive the conversion */")
        for (qualified, fname), mask in sorted(self.bit_masks.items()):
            var = self.var(self.src, qualified, "s")
            value = f"(uint64_t){var}->{ident(fname)} & ~(uint64_t){mask}u"
            guard = f"{var} != NULL && " if self.optional(qualified) else ""
            label = f'"{qualified}.{fname}"'
            self.emit(f"if ({guard}({value}) != 0u) {{ battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, {label}); }}")
        if self.src is None:
            for name in self.concepts:
                if (CONCEPTS_ENDPOINT, name) not in self.read:
                    add = f'battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, "concepts.{name}");'
                    self.emit(f"if (s->has_{ident(name)}) {{ {add} }}")
        else:
            for qualified in self.src.messages:
                self.report_unread(qualified)
        if self.dst is None:
            return
        for qualified in self.dst.messages:
            var = self.var(self.dst, qualified, "t")
            for f in self.schema.message(qualified).fields:
                if f.is_padding or (qualified, f.name) in self.written:
                    continue
                self.emit(f'battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, "{qualified}.{f.name}");')
            if self.src is None:
                continue
            for f in self.schema.message(qualified).fields:
                if f.invalid is None or (qualified, f.name) not in self.written:
                    continue
                add = f'battgen_loss_add(rep_u, BATTGEN_LOSS_UNKNOWN, "{qualified}.{f.name}");'
                self.emit(*self.marker_test(f, f"{var}->{ident(f.name)}", add))

    def report_unread(self, qualified: str) -> None:
        assert self.src is not None
        var = self.var(self.src, qualified, "s")
        msg = self.schema.message(qualified)
        unread = [f for f in msg.fields if not f.is_padding and (qualified, f.name) not in self.read]
        if not unread:
            return
        fn = self.defaults_fn(qualified)
        checks: list[str] = []
        for f in unread:
            lines = differs(self.schema, f.type, f"{var}->{ident(f.name)}", f"fresh.{ident(f.name)}")
            checks += ["d = false;", *lines]
            checks.append(f'if (d) {{ battgen_loss_add(rep_d, BATTGEN_LOSS_DROPPED, "{qualified}.{f.name}"); }}')
        loops = any("[i]" in line for line in checks)
        self.emit(
            f"if (rep_d != NULL && {var} != NULL) {{",
            f"{c_type(qualified)} fresh;",
            "bool d;",
            *(["size_t i;"] if loops else []),
            f"{fn}(&fresh);",
            *checks,
            "}",
        )

    def marker_test(self, f: Field, attr: str, add: str) -> list[str]:
        """Statements doing ``add`` when the field holds its "unknown" marker (Python's is_marker)."""
        s = f.invalid
        assert s is not None
        p = primitive(f)
        if p is None:
            raise Unsupported("a marker on text")

        def one(x: str) -> str:
            if isinstance(s.value, float) and math.isnan(s.value):
                if p.kind is not PrimitiveKind.FLOAT:
                    return "false"
                return f"battgen_f{64 if p.bits > 32 else 32}_is_nan({x})"
            if p.kind is PrimitiveKind.BOOL:
                return f"{x} == {'true' if s.value else 'false'}"
            return f"{x} == {literal(p, s.value)}"

        t = f.type
        if not isinstance(t, ArrayType):
            return [f"if ({one(attr)}) {{ {add} }}"]
        n = f"{attr}_len" if t.dynamic else f"{t.capacity or 1}u"
        if s.first_decides:
            return [f"if ({n} > 0u && {one(attr + '[0]')}) {{ {add} }}"]
        if s.per_element:  # every element at the marker (an empty array too)
            return [
                "{",
                "size_t i;",
                "bool all = true;",
                f"for (i = 0; i < {n}; i++) {{",
                f"if (!({one(attr + '[i]')})) {{ all = false; }}",
                "}",
                f"if (all) {{ {add} }}",
                "}",
            ]
        return []  # a list is never equal to a number


def _edges(schema: Schema) -> list[Edge]:
    """Every direction of every mapping, as the Python backend's route finder takes them."""
    out = []
    for m in (m for s in schema.mappings for m in s.mappings):
        out.append(Edge(m.source, m.target, "forward", m))
        if m.reversible:
            out.append(Edge(m.target, m.source, "backward", m))
    return out


def c_converters(schema: Schema) -> tuple[list[CConverter], dict[str, str], list[str]]:
    """(the converters, the static functions they use by name -- helpers and map functions --, the
    converters of the Python package left out, with why)."""
    helpers: dict[str, list[str]] = {}
    endpoints = {e.name: e for s in schema.mappings for e in s.endpoints}
    concepts: dict[str, Concept] = {c.name: c for s in schema.mappings for c in s.concepts}
    functions: dict[tuple[str, str], MapFunction | str] = {}  # (mapping, direction) -> function or why not

    def function(e: Edge) -> MapFunction | str:
        key = (e.mapping.name, e.function)
        if key not in functions:
            sides = [None if n == CONCEPTS_ENDPOINT else endpoints[n] for n in (e.source, e.target)]
            if any(schema.message(q).format not in _FORMATS for side in sides if side for q in side.messages):
                functions[key] = f"{e.mapping.name}: no C codec for its messages"
                return functions[key]
            saved = dict(helpers)
            b = _Builder(schema, e.mapping, sides[0], sides[1], e.function == "backward", concepts, helpers)
            try:
                body = b.build()
                name = f"map_{ident(e.mapping.name)}_{e.function}"
                targets = list(sides[1].messages) if sides[1] is not None else []
                functions[key] = MapFunction(e, name, b.params(), b.unused() + body, list(b.inputs), targets)
            except Unsupported as why:
                helpers.clear()
                helpers.update(saved)
                functions[key] = f"{e.mapping.name} ({e.function}): {why}"
        return functions[key]

    edges = _edges(schema)
    made: list[CConverter] = []
    left: list[str] = []
    names = [n for n, ep in endpoints.items() if all(schema.message(q).format in _FORMATS for q in ep.messages)]
    for a in names:
        for b_name in names:
            if a == b_name:
                continue
            for policy in POLICIES:
                path = route(edges, a, b_name, policy)
                if not path:
                    continue
                chain = [function(e) for e in path]
                why = [c for c in chain if isinstance(c, str)]
                if why:
                    left += [w for w in why if w not in left]
                    continue
                fns = [c for c in chain if isinstance(c, MapFunction)]
                src, dst = endpoints[a], endpoints[b_name]
                made.append(
                    CConverter(
                        a,
                        b_name,
                        policy,
                        f"battgen_convert_{ident(a)}_to_{ident(b_name)}_{policy}",
                        [
                            (q, ident(alias), i > 0)
                            for i, (q, alias) in enumerate(zip(src.messages, src.aliases, strict=True))
                        ],
                        [(q, f"out_{ident(alias)}") for q, alias in zip(dst.messages, dst.aliases, strict=True)],
                        fns[0].inputs,
                        fns,
                    )
                )
    used = {f.name: f for c in made for f in c.chain}
    text = "\n".join(line for f in used.values() for line in f.body)
    static = {k: "\n".join(v) for k, v in sorted(helpers.items()) if f"{k}(" in text}
    for name, f in sorted(used.items()):
        static[name] = "\n".join([f"static void {name}({', '.join(f.params)}) {{", *f.body, "}"])
    return made, static, left
