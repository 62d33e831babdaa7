"""The converters as Rust, generated from the mappings rule by rule as the C backend writes them
(``codegen/backends/c/converters.py``) and along the same routes (:mod:`codegen.ir.mapping_routes`):
each direction of a mapping is a private function (``map_<mapping>_<direction>``, its sides an
endpoint's messages or the concepts, ``Concepts``), and each converter between two formats of the
crate, per policy, is a public function chaining them (``<source>_to_<target>_<policy>``): strict
through the concepts (f64, as Python computes), px4 through PX4's own code paths (f32 at every
step, float16 rounded to nearest even as received, C's float to integer conversions). The loss
report gets the Python report's entries (kind and field; the detail text is not kept).

A mapping holding an op not written in Rust raises :class:`Unsupported`; a converter needing it is
left out, and :func:`rust_converters` says which (the README lists them).
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
from .convert_values import Unsupported, defaults, differs, literal, primitive, rust_type
from .naming import field_ident, snake
from .types import capacity, scalar

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
    """One direction of one mapping as a private Rust function."""

    edge: Edge
    name: str
    params: list[str]  # Rust parameters, the report last
    body: list[str]
    inputs: list[str]
    targets: list[str]  # the qualified messages it writes (none: the concepts)


def _path(qualified: str) -> str:
    return rust_type(qualified)


@dataclass(frozen=True)
class RustConverter:
    """A public converter: source side -> target side under one policy, a chain of map functions."""

    source: str
    target: str
    policy: str
    name: str
    sources: list[tuple[str, str, bool]]  # (qualified, parameter, optional)
    targets: list[tuple[str, str]]  # (qualified, variable)
    inputs: list[str]
    chain: list[MapFunction]

    def signature(self) -> str:
        params = [f"{v}: Option<&{_path(q)}>" if opt else f"{v}: &{_path(q)}" for q, v, opt in self.sources]
        params += [f"{name}: Option<f32>" for name in self.inputs]
        params.append("rep: &mut LossReport")
        outs = [_path(q) for q, _ in self.targets]
        result = outs[0] if len(outs) == 1 else "(" + ", ".join(outs) + ")"
        return f"pub fn {self.name}({', '.join(params)}) -> {result}"

    def route(self) -> str:
        return " -> ".join(f.edge.mapping.name for f in self.chain)

    def body(self) -> list[str]:
        """The calls along the route; a loss reported where it happens, as the Python converter does."""
        out: list[str] = []
        between: list[list[str]] = []  # each intermediate stage's objects
        for i, f in enumerate(self.chain[:-1], 1):
            if not f.targets:
                out.append(f"let mut c{i} = {STATE}::new();")
                between.append([f"c{i}"])
            else:
                out += [f"let mut c{i}_{k} = {_path(q)}::new();" for k, q in enumerate(f.targets)]
                between.append([f"c{i}_{k}" for k in range(len(f.targets))])
        out += [f"let mut {v} = {_path(q)}::new();" for q, v in self.targets]
        after_firmware = False
        for i, f in enumerate(self.chain):
            first, last = i == 0, i == len(self.chain) - 1
            e = f.edge
            if first:
                args = [v for _, v, _ in self.sources]
                args += [n if n in self.inputs else "None" for n in f.inputs]
            else:
                prev = between[i - 1]
                args = [f"&{v}" for v in prev[:1]] + [f"Some(&{v})" for v in prev[1:]]
                args += ["None" for _ in f.inputs]
            args += [f"&mut {v}" for _, v in self.targets] if last else [f"&mut {v}" for v in between[i]]
            dropped = first or e.source == CONCEPTS_ENDPOINT or not after_firmware
            args.append(f"&mut Reports::new(rep, {str(dropped).lower()}, {str(last).lower()})")
            out.append(f"{f.name}({', '.join(args)});")
            after_firmware = after_firmware or e.mapping.policy in FIRMWARE_POLICIES
        outs = [v for _, v in self.targets]
        out.append(outs[0] if len(outs) == 1 else "(" + ", ".join(outs) + ")")
        return out


class _Builder(PX4Ops, PX4CellOps, ConceptCellOps):
    """One direction of one mapping as Rust (see the module docstring)."""

    def _unsupported(self, rule: Rule, op: object) -> None:
        raise Unsupported(f"op {rule.op.NAME}")

    visit_dt_pack = visit_ocv_soc = visit_px4_udral_energy = _unsupported
    # ArduPilot's DroneCAN monitor (the ardupilot policy): not written in C or Rust yet
    visit_ardupilot_temperature = visit_ardupilot_current = _unsupported
    visit_ardupilot_cells = visit_ardupilot_estimates = _unsupported
    visit_value_flags = _unsupported  # one condition of several as flags (UDRAL's error): no UDRAL codec yet

    # -- the function ----------------------------------------------------------------------

    def defaults_fn(self, qualified: str) -> str:
        fn = f"defaults_{snake(qualified)}"
        self.helpers[fn] = [
            f"fn {fn}(m: &mut {_path(qualified)}) {{",
            *defaults(self.schema, self.schema.message(qualified), "m"),
            "}",
        ]
        return fn

    def params(self) -> list[str]:
        """The function's parameters: sources (after the first optional), inputs, targets, the report."""
        out: list[str] = []
        for side, prefix in ((self.src, "s"), (self.dst, "t")):
            if side is None:
                out.append(f"{prefix}: &{'mut ' if prefix == 't' else ''}{STATE}")
            else:
                for k, q in enumerate(side.messages):
                    var = self.var(side, q, prefix)
                    if prefix == "t":
                        out.append(f"{var}: &mut {_path(q)}")
                    else:
                        out.append(f"{var}: Option<&{_path(q)}>" if k > 0 else f"{var}: &{_path(q)}")
            if prefix == "s":
                out += [f"{name}: Option<f32>" for name in self.inputs]
        return [*out, "r: &mut Reports<'_>"]

    def build(self) -> list[str]:
        if self.dst is None:
            self.emit(f"*t = {STATE}::new();")
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
            self.emit(f"// {where}{rule.op.NAME}")
            start = len(self.lines)
            visit(rule, self)
            block = self.lines[start:]
            del self.lines[start:]
            if optional and not rule.op.HANDLES_MISSING:
                names = ", ".join(optional)
                somes = ", ".join(f"Some({v})" for v in optional)
                if len(optional) == 1:
                    self.emit(f"if let {somes} = {names} {{", *block, "}")
                else:
                    self.emit(f"if let ({somes}) = ({names}) {{", *block, "}")
            else:
                self.emit("{", *block, "}")
        self.epilogue()
        return self.lines

    def unused(self) -> list[str]:
        """``let _ = p;`` for every parameter a mapping may not use (an optional message, an input)."""
        out = []
        for p in self.params():
            name = p.split(":")[0]
            if name != "r":
                out.append(f"let _ = &{name};")
        return out

    def epilogue(self) -> None:
        """Source bits and fields nobody read (a field differing from a fresh message's), concepts nobody
        read, target fields no rule wrote, and between formats those left at their "unknown" marker:
        as the Python mapping function reports them."""
        self.emit("// what did not survive the conversion")
        for (qualified, fname), mask in sorted(self.bit_masks.items()):
            var = self.var(self.src, qualified, "s")
            rust = primitive(self.schema.field_at(qualified, fname))
            assert rust is not None
            value = self.bits(f"{var}.{field_ident(fname)}", scalar(rust))
            label = f'"{qualified}.{fname}"'
            test = f"if {value} & !{mask}_u64 != 0 {{ r.add_d(LossKind::Dropped, {label}); }}"
            if self.optional(qualified):
                self.emit(f"if let Some({var}) = {var} {{", test, "}")
            else:
                self.emit(test)
        if self.src is None:
            for name in self.concepts:
                if (CONCEPTS_ENDPOINT, name) not in self.read:
                    add = f'r.add_d(LossKind::Dropped, "concepts.{name}");'
                    self.emit(f"if s.has_{field_ident(name)} {{ {add} }}")
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
                self.emit(f'r.add_u(LossKind::Unknown, "{qualified}.{f.name}");')
            if self.src is None:
                continue
            for f in self.schema.message(qualified).fields:
                if f.invalid is None or (qualified, f.name) not in self.written:
                    continue
                add = f'r.add_u(LossKind::Unknown, "{qualified}.{f.name}");'
                self.emit(*self.marker_test(f, f"{var}.{field_ident(f.name)}", add))

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
            test = differs(f.type, f"{var}.{field_ident(f.name)}", f"fresh.{field_ident(f.name)}")
            checks.append(f'if {test} {{ r.add_d(LossKind::Dropped, "{qualified}.{f.name}"); }}')
        head = (
            f"if let (true, Some({var})) = (r.dropped(), {var}) {{" if self.optional(qualified) else "if r.dropped() {"
        )
        self.emit(head, f"let mut fresh = {_path(qualified)}::new();", f"{fn}(&mut fresh);", *checks, "}")

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
                return f"{x}.is_nan()"
            if p.kind is PrimitiveKind.BOOL:
                return x if s.value else f"!{x}"
            return f"{x} == {literal(p, s.value)}"

        t = f.type
        if not isinstance(t, ArrayType):
            test = one(attr)
            return [] if test == "false" else [f"if {test} {{ {add} }}"]
        n = f"{attr}_len.min({capacity(t)})" if t.dynamic else f"{t.capacity or 1}"
        if s.first_decides:
            test = one(attr + "[0]")
            return [] if test == "false" else [f"if {n} > 0 && {test} {{ {add} }}"]
        if s.per_element:  # every element at the marker (an empty array too)
            return [f"if {attr}[..{n}].iter().all(|x| {one('*x')}) {{ {add} }}"]
        return []  # a list is never equal to a number


def _edges(schema: Schema) -> list[Edge]:
    """Every direction of every mapping, as the Python backend's route finder takes them."""
    out = []
    for m in (m for s in schema.mappings for m in s.mappings):
        out.append(Edge(m.source, m.target, "forward", m))
        if m.reversible:
            out.append(Edge(m.target, m.source, "backward", m))
    return out


def rust_converters(schema: Schema) -> tuple[list[RustConverter], dict[str, str], list[str]]:
    """(the converters, the private functions they use by name -- helpers and map functions --, the
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
                functions[key] = f"{e.mapping.name}: no Rust codec for its messages"
                return functions[key]
            saved = dict(helpers)
            b = _Builder(schema, e.mapping, sides[0], sides[1], e.function == "backward", concepts, helpers)
            try:
                body = b.build()
                name = f"map_{snake(e.mapping.name)}_{e.function}"
                targets = list(sides[1].messages) if sides[1] is not None else []
                functions[key] = MapFunction(e, name, b.params(), b.unused() + body, list(b.inputs), targets)
            except Unsupported as why:
                helpers.clear()
                helpers.update(saved)
                functions[key] = f"{e.mapping.name} ({e.function}): {why}"
        return functions[key]

    edges = _edges(schema)
    made: list[RustConverter] = []
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
                    RustConverter(
                        a,
                        b_name,
                        policy,
                        f"{snake(a)}_to_{snake(b_name)}_{policy}",
                        [
                            (q, snake(alias), i > 0)
                            for i, (q, alias) in enumerate(zip(src.messages, src.aliases, strict=True))
                        ],
                        [(q, f"out_{snake(alias)}") for q, alias in zip(dst.messages, dst.aliases, strict=True)],
                        fns[0].inputs,
                        fns,
                    )
                )
    used = {f.name: f for c in made for f in c.chain}
    text = "\n".join(line for f in used.values() for line in f.body)
    static = {k: "\n".join(v) for k, v in sorted(helpers.items()) if f"{k}(" in text}
    for name, f in sorted(used.items()):
        static[name] = "\n".join([f"fn {name}({', '.join(f.params)}) {{", *f.body, "}"])
    return made, static, left
