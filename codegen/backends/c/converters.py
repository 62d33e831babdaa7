"""The converters as C: one function per mapping whose both ends are messages of the C library
(px4 mappings between formats), written rule by rule from the mapping IR as the Python backend
writes ``generated/convert/_map_<mapping>.py`` -- the same float32 arithmetic (C floats, float16
rounded to nearest even as received), the same C integer conversions, the same loss report
entries (kind and field; the Python report's detail text is not kept).

A mapping holding an op not written here yet (the concept mappings of the strict policy, the
MAVLink cell algorithms) raises :class:`Unsupported` and is left out; :func:`c_converters` says
which.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...ir import (
    CONCEPTS_ENDPOINT,
    ArrayType,
    Direction,
    Endpoint,
    Field,
    FieldRef,
    Mapping,
    PrimitiveKind,
    PrimitiveType,
    Rule,
    Schema,
    SourceFormat,
    units,
)
from ...ir import ops as o
from ...ir.mapping_values import ConstantRef, Value
from ...ir.mapping_visitor import visit
from .convert_values import Unsupported, c_type, defaults, differs, f32_literal, int_literal, literal, primitive
from .types import ident, scalar

FLT_EPS = 1.1920928955078125e-07
_FORMATS = (SourceFormat.DRONECAN, SourceFormat.MAVLINK, SourceFormat.UORB)


def _f32(x: float) -> float:
    import struct

    value: float = struct.unpack("<f", struct.pack("<f", x))[0]
    return value


@dataclass
class CConverter:
    """One generated converter function."""

    mapping: Mapping
    name: str  # the C function
    sources: list[tuple[str, str, bool]]  # (qualified, variable, optional)
    targets: list[tuple[str, str]]  # (qualified, variable)
    inputs: list[str]
    body: list[str]
    doc: str = ""
    helpers: list[str] = field(default_factory=list)

    def prototype(self) -> str:
        params = [f"const {c_type(q)} *{v}" for q, v, _ in self.sources]
        params += [f"const float *{name}" for name in self.inputs]
        params += [f"{c_type(q)} *{v}" for q, v in self.targets]
        params.append("battgen_loss_report *rep")
        return f"void {self.name}({', '.join(params)})"


class _Builder:
    """One direction of one mapping as C statements (see the module docstring)."""

    def __init__(
        self, schema: Schema, mapping: Mapping, src: Endpoint, dst: Endpoint, helpers: dict[str, list[str]]
    ) -> None:
        self.schema = schema
        self.helpers = helpers  # functions the converters share, by name
        self.mapping = mapping
        self.src = src
        self.dst = dst
        self.lines: list[str] = []
        self.inputs: list[str] = []
        self.read: set[tuple[str, str]] = set()
        self.written: set[tuple[str, str]] = set()

    # -- names -----------------------------------------------------------------------------

    def var(self, side: Endpoint, qualified: str, prefix: str) -> str:
        return f"{prefix}_{ident(side.aliases[side.messages.index(qualified)])}"

    def optional(self, qualified: str) -> bool:
        return self.src.messages.index(qualified) > 0

    def fld(self, ref: FieldRef) -> Field:
        return self.schema.field_at(ref.message, ref.field)

    def attr(self, ref: FieldRef) -> str:
        head, *steps = ref.field.split(".")
        out = ident(head)
        t = self.schema.message(ref.message).field(head).type
        for step in steps:
            if isinstance(t, ArrayType):
                out += f"[{int(step)}]"
                t = t.element
            else:
                from ...ir import CompositeType

                assert isinstance(t, CompositeType), ref
                out += "." + ident(step)
                t = self.schema.message(t.name).field(step).type
        return out

    def s(self, ref: FieldRef) -> str:
        self.read.add((ref.message, ref.field))
        self.read.add((ref.message, ref.field.split(".")[0]))
        return f"{self.var(self.src, ref.message, 's')}->{self.attr(ref)}"

    def t(self, ref: FieldRef) -> str:
        self.written.add((ref.message, ref.field))
        self.written.add((ref.message, ref.field.split(".")[0]))
        return f"{self.var(self.dst, ref.message, 't')}->{self.attr(ref)}"

    def label(self, ref: FieldRef) -> str:
        return f'"{ref.message}.{ref.field}"'

    def prim(self, ref: FieldRef) -> PrimitiveType:
        p = primitive(self.fld(ref))
        if p is None:
            raise Unsupported(f"{ref.field} is not a number")
        return p

    def constant_value(self, name: str, refs: tuple[FieldRef, ...] | list[FieldRef]) -> int | float | bool | str:
        for ref in refs:
            for c in self.schema.message(ref.message).constants:
                if c.name == name:
                    return c.value
        for e in self.schema.enums:
            for entry in e.entries:
                if entry.name == name:
                    return entry.value
        raise Unsupported(f"no constant {name!r}")

    def value_of(self, value: Value | None, refs: tuple[FieldRef, ...] | list[FieldRef]) -> object:
        return self.constant_value(value.name, refs) if isinstance(value, ConstantRef) else value

    def mask(self, name: ConstantRef, refs: tuple[FieldRef, ...] | list[FieldRef]) -> int:
        value = self.constant_value(name.name, refs)
        for ref in refs:
            for e in self.schema.message(ref.message).enums:
                if any(x.name == name.name for x in e.entries) and e.kind.value == "bit_index":
                    return 1 << int(value)
        return int(value)

    def emit(self, *lines: str) -> None:
        self.lines.extend(lines)

    # -- values as PX4 holds them --------------------------------------------------------

    def px4_read(self, ref: FieldRef, expr: str | None = None) -> str:
        """A source value in a C float; a DroneCAN float16 as it came off the wire."""
        value = expr or self.s(ref)
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT and p.bits == 16:
            return f"battgen_f16_round({value}, NULL, NULL)"
        if p.kind is PrimitiveKind.FLOAT and p.bits == 32:
            return value
        if p.kind is PrimitiveKind.BOOL:
            return f"({value} ? 1.0f : 0.0f)"
        return f"(float){value}"

    def store_c(self, ref: FieldRef, expr: str) -> str:
        """A C assignment of the float32 ``expr`` to the field's type (then DroneCAN's saturation)."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            if p.bits == 16:
                return f"battgen_f16_round({expr}, rep, {self.label(ref)})"
            return expr if p.bits == 32 else f"(double)({expr})"
        if p.kind is PrimitiveKind.BOOL:
            return f"(({expr}) != 0.0f)"
        signed = p.kind is PrimitiveKind.INT
        c = scalar(p)
        storage = int(c.removeprefix("u").removeprefix("int")[:-2])
        fn = f"cvt_{'i' if signed else 'u'}{storage}" + ("" if storage == p.bits else f"_{p.bits}")
        self.helper_cvt(fn, c, signed, storage, p)
        return f"{fn}({expr}, rep, {self.label(ref)})"

    def helper_cvt(self, fn: str, c: str, signed: bool, storage: int, p: PrimitiveType) -> None:
        body = [f"static {c} {fn}(float x, battgen_loss_report *rep, const char *field) {{"]
        if signed:
            body.append(f"{c} v = battgen_i{storage}((uint{storage}_t)(uint32_t)battgen_vcvt_s32(x));")
        else:
            body.append(f"{c} v = ({c})battgen_vcvt_u32(x);")
        body.append(
            "if (battgen_float_int_lost(x, (int64_t)v)) { battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field); }"
        )
        if storage != p.bits:  # DroneCAN's saturated odd width
            lo, hi = (int(v) for v in p.value_range or (0, 0))
            body.append(f"if (v < {int_literal(lo, c)}) {{ v = {int_literal(lo, c)}; }}" if signed else "")
            body.append(f"if (v > {int_literal(hi, c)}) {{ v = {int_literal(hi, c)}; }}")
        body += ["return v;", "}"]
        self.helpers[fn] = [line for line in body if line]

    def int_store(self, ref: FieldRef, expr: str) -> str:
        """The integer ``expr`` (an int64_t) as C keeps it in the field, then a DroneCAN odd width saturated."""
        p = self.prim(ref)
        if p.kind is PrimitiveKind.BOOL:
            return f"(({expr}) != 0)"
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer into a float field")
        c = scalar(p)
        storage = int(c.removeprefix("u").removeprefix("int")[:-2])
        raw = f"(uint{storage}_t)(uint64_t)({expr})"
        value = raw if p.kind is PrimitiveKind.UINT else f"battgen_i{storage}({raw})"
        if storage == p.bits:
            return value
        lo, hi = (int(v) for v in p.value_range or (0, 0))
        fn = f"saturate_{c[:-2]}_{p.bits}"
        self.helpers[fn] = [
            f"static {c} {fn}({c} v) {{",
            *([f"if (v < {int_literal(lo, c)}) {{ return {int_literal(lo, c)}; }}"] if lo < 0 else []),
            f"return v > {int_literal(hi, c)} ? {int_literal(hi, c)} : v;",
            "}",
        ]
        return f"{fn}({value})"

    def int_source(self, ref: FieldRef) -> str:
        p = self.prim(ref)
        if p.kind is PrimitiveKind.FLOAT:
            raise Unsupported("an integer op on a float")
        return f"(int64_t){self.s(ref)}"

    # -- the ops ---------------------------------------------------------------------------

    def visit_zero_all(self, rule: Rule, op: o.ZeroAll) -> None:
        for ref in rule.targets:
            var = self.var(self.dst, ref.message, "t")
            for f in self.schema.message(ref.message).fields:
                if f.invalid is None or f.is_padding:
                    continue
                t = f.type
                name = f"{var}->{ident(f.name)}"
                if isinstance(t, ArrayType):
                    if t.dynamic:
                        raise Unsupported("zeroing a dynamic array")
                    self.emit(f"battgen_zero({name}, sizeof {name});")
                elif isinstance(t, PrimitiveType):
                    self.emit(f"{name} = {literal(t, 0)};")
                else:
                    raise Unsupported("zeroing text")

    def visit_const(self, rule: Rule, op: o.Const) -> None:
        value = self.value_of(op.value, rule.targets)
        for ref in rule.targets:
            if ref.message == CONCEPTS_ENDPOINT or not isinstance(self.fld(ref).type, PrimitiveType):
                raise Unsupported("a constant into a concept or an array")
            self.emit(f"{self.t(ref)} = {literal(self.prim(ref), value)};")

    def visit_px4_convert(self, rule: Rule, op: o.PX4Convert) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        self.emit(f"float x = {self.px4_read(src)};")
        if op.convert is o.PX4Conversion.UNITS:
            su = units.lookup(op.source_unit) if op.source_unit else self.fld(src).unit
            tu = units.lookup(op.target_unit) if op.target_unit else self.fld(dst).unit
            if su is None or tu is None:
                raise Unsupported("px4_convert without units")
            mul, add = su.factor_to(tu)
            if mul != 1.0:
                if op.form is o.PX4Form.DIVIDE:
                    self.emit(f"x = x / {f32_literal(_f32(1.0 / mul))};")
                else:
                    self.emit(f"x = x * {f32_literal(_f32(mul))};")
            if add != 0.0:
                self.emit(f"x = x + {f32_literal(_f32(add))};")
        if op.round:
            raise Unsupported("roundf")
        value = self.store_c(dst, "x")
        p = self.prim(dst)
        if op.at_least is not None:
            k = literal(p, op.at_least)
            self.emit(f"{scalar(p)} y = {value};")
            value = f"({k} > y ? {k} : y)"
        tests = []
        if op.guard is not None:
            tests.append(f"({self.s(FieldRef(src.message, op.guard))} != 0)")
        if op.finite:
            tests.append("!battgen_f32_is_nan(x) && !battgen_f32_is_inf(x)")
        if op.above is not None:
            tests.append(f"x > {f32_literal(_f32(float(op.above)))}")
        target = self.t(dst)
        if not tests:
            self.emit(f"{target} = {value};")
            return
        otherwise = self.value_of(op.otherwise if op.otherwise is not None else 0, [dst])
        self.emit(
            f"if ({' && '.join(tests)}) {{",
            f"{target} = {value};",
            "} else {",
            f"{target} = {literal(p, otherwise)};",
            "}",
        )

    def visit_px4_int(self, rule: Rule, op: o.PX4Int) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        expr = self.int_source(src)
        if op.mask is not None:
            expr = f"({expr} & {self.mask(op.mask, [src])}LL)"
        if op.add:
            expr = f"({expr} + {int(op.add)}LL)"
        self.emit(f"{self.t(dst)} = {self.int_store(dst, expr)};")

    def visit_px4_warning(self, rule: Rule, op: o.PX4Warning) -> None:
        dst = rule.targets[0]
        level = self.t(FieldRef(dst.message, op.of))
        target = self.t(dst)
        p = self.prim(dst)
        self.emit(f"float s = {level};")
        chain = (
            ("if", "emergency", op.emergency),
            ("} else if", "critical", op.critical),
            ("} else if", "low", op.low),
        )
        for keyword, name, threshold in chain:
            value = self.constant_value(f"WARNING_{name.upper()}", [dst])
            self.emit(f"{keyword} (s < {f32_literal(_f32(float(threshold)))}) {{", f"{target} = {literal(p, value)};")
        none = self.constant_value("WARNING_NONE", [dst])
        self.emit("} else {", f"{target} = {literal(p, none)};", "}")

    def visit_enum_map(self, rule: Rule, op: o.EnumMap) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        p = self.prim(dst)
        default = self.value_of(op.default if op.default is not None else 0, [dst])
        self.emit(f"switch ({self.int_source(src)}) {{")
        seen: set[object] = set()
        for pair in op.map:
            key = self.value_of(pair.source, [src])
            if not isinstance(key, int):
                raise Unsupported(f"the key {key!r}")
            if key in seen:  # Python's dict keeps the last; none of the mappings repeats a key
                raise Unsupported("a repeated key")
            seen.add(key)
            value = literal(p, self.value_of(pair.target, [dst]))
            self.emit(f"case {key}LL:", f"{self.t(dst)} = {value};", "break;")
        self.emit("default:", f"{self.t(dst)} = {literal(p, default)};", "break;", "}")

    def visit_bits_from(self, rule: Rule, op: o.BitsFrom) -> None:
        dst = rule.targets[0]
        self.emit("uint64_t b = 0u;")
        for bit in op.bits:
            src = FieldRef(rule.sources[0].message, bit.field)
            cond = f"{self.s(src)} != 0"
            if bit.equals is not None:
                value = self.value_of(bit.equals, [src])
                cond = f"{self.s(src)} == {literal(self.prim(src), value)}"
            self.emit(f"if ({cond}) {{ b |= {self.mask(bit.mask, [dst])}ULL; }}")
        self.emit(f"{self.t(dst)} = {self.int_store(dst, '(int64_t)b')};")

    def visit_px4_bridge_cells(self, rule: Rule, op: o.PX4BridgeCells) -> None:
        volt, aux_cells = rule.sources
        cells, count = rule.targets
        t = self.fld(cells).type
        assert isinstance(t, ArrayType)
        cap = t.capacity or 0
        aux = self.var(self.src, aux_cells.message, "s")
        target = self.t(cells)
        self.emit(
            "size_t i;",
            f"for (i = 0; i < {cap}u; i++) {{ {target}[i] = 0.0f; }}",
            f"{target}[0] = {self.px4_read(volt)};",
            f"if ({aux} == NULL) {{",
            f"{self.t(count)} = 1;",
            "} else {",
            f"size_t n = (size_t)({self.s(aux_cells)}_len & 0xFFu);",
            f"if (n > {cap}u) {{ n = {cap}u; }}",
            "for (i = 0; i < n; i++) {",
            f"{target}[i] = {self.px4_read(aux_cells, f'{self.s(aux_cells)}[i]')};",
            "}",
            f"{self.t(count)} = ({scalar(self.prim(count))})n;",
            "}",
        )

    def visit_px4_aux_capacity(self, rule: Rule, op: o.PX4AuxCapacity) -> None:
        energy, voltage = rule.sources
        dst = rule.targets[0]
        ah = units.lookup("Ah")
        unit = self.fld(dst).unit
        mul = ah.factor_to(unit)[0] if ah is not None and unit is not None else 1.0
        eps = _f32(float(op.above if op.above is not None else FLT_EPS))
        value = f"(({self.px4_read(energy)} * {f32_literal(_f32(mul))}) / v)"
        self.emit(
            f"float v = {self.px4_read(voltage)};",
            f"if (v > {f32_literal(eps)}) {{",
            f"{self.t(dst)} = {self.store_c(dst, value)};",
            "}",
        )

    def visit_px4_bridge_estimates(self, rule: Rule, op: o.PX4BridgeEstimates) -> None:
        current, aux = rule.sources
        discharged, remaining_time, average = rule.targets
        dt, total = ident(op.dt_input), ident(op.discharged_input)
        for name in (dt, total):
            if name not in self.inputs:
                self.inputs.append(name)
        soc = self.t(FieldRef(discharged.message, op.soc_of))
        capacity = self.t(FieldRef(discharged.message, op.capacity_of))
        eps = f32_literal(FLT_EPS)
        self.emit(
            f"float v = {total} == NULL ? 0.0f : *{total};",
            f"if ({self.var(self.src, aux.message, 's')} == NULL) {{",
            "/* Battery::updateDt (at most 2 s) and Battery::sumDischarged(fabsf(msg.current)) */",
            f"float x = battgen_absf({self.px4_read(current)});",
            f"float t = {dt} == NULL ? 0.0f : (2.0f < *{dt} ? 2.0f : *{dt});",
            f"if (t > {eps}) {{",
            "v = v + (x * 1000.0f) * (t / 3600.0f);",
            "}",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "} else {",
            "/* Battery::computeRemainingTime while disarmed: the average filter reset to BAT_AVRG_CURRENT */",
            f"float m = {f32_literal(_f32(float(op.average_current)))};",
            "float cap, s, d;",
            f"{self.t(average)} = m;",
            f"cap = (float){capacity};",
            f"s = {soc};",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "if (cap > 0.0f) {",
            "d = m * 1000.0f;",
            f"d = {eps} > d ? {eps} : d;",
            f"{self.t(remaining_time)} = ((s * cap) / d) * 3600.0f;",
            "}",
            "}",
            f"{self.t(discharged)} = v;",
        )

    def _unsupported(self, rule: Rule, op: object) -> None:
        raise Unsupported(f"op {rule.op.NAME}")

    visit_scale = visit_copy = visit_soc_hybrid = visit_flag = visit_flag_choice = _unsupported
    visit_flags = visit_choice = visit_cells = visit_mavlink_voltages = visit_dt_pack = _unsupported
    visit_ocv_soc = visit_same_names = visit_px4_stream_cells = visit_px4_receiver_cells = _unsupported
    visit_px4_cell_list = visit_px4_udral_energy = _unsupported

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

    def build(self) -> list[str]:
        for qualified in self.dst.messages:  # what a fresh Python object holds
            self.emit(f"{self.defaults_fn(qualified)}({self.var(self.dst, qualified, 't')});")
        for rule in self.mapping.rules:
            if rule.only is Direction.BACKWARD:
                continue
            optional = sorted({self.var(self.src, r.message, "s") for r in rule.sources if self.optional(r.message)})
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
        """``(void)p;`` for every parameter (an optional message or input a mapping may not read)."""
        names = [self.var(self.src, q, "s") for q in self.src.messages] + self.inputs + ["rep"]
        return [f"(void){n};" for n in names]

    def epilogue(self) -> None:
        """Source fields nobody read (differing from a fresh message's), target fields no rule wrote,
        and written ones left at their "unknown" marker: as the Python converter reports them."""
        self.emit("/* what did not survive the conversion */")
        for qualified in self.src.messages:
            var = self.var(self.src, qualified, "s")
            msg = self.schema.message(qualified)
            unread = [f for f in msg.fields if not f.is_padding and (qualified, f.name) not in self.read]
            if not unread:
                continue
            fn = self.defaults_fn(qualified)
            checks: list[str] = []
            for f in unread:
                lines = differs(self.schema, f.type, f"{var}->{ident(f.name)}", f"fresh.{ident(f.name)}")
                checks += ["d = false;", *lines]
                checks.append(f'if (d) {{ battgen_loss_add(rep, BATTGEN_LOSS_DROPPED, "{qualified}.{f.name}"); }}')
            loops = any("[i]" in line for line in checks)
            self.emit(
                f"if (rep != NULL && {var} != NULL) {{",
                f"{c_type(qualified)} fresh;",
                "bool d;",
                *(["size_t i;"] if loops else []),
                f"{fn}(&fresh);",
                *checks,
                "}",
            )
        for qualified in self.dst.messages:
            var = self.var(self.dst, qualified, "t")
            for f in self.schema.message(qualified).fields:
                if f.is_padding or (qualified, f.name) in self.written:
                    continue
                self.emit(f'battgen_loss_add(rep, BATTGEN_LOSS_UNKNOWN, "{qualified}.{f.name}");')
            for f in self.schema.message(qualified).fields:
                if f.invalid is None or (qualified, f.name) not in self.written:
                    continue
                add = f'battgen_loss_add(rep, BATTGEN_LOSS_UNKNOWN, "{qualified}.{f.name}");'
                self.emit(*self.marker_test(f, f"{var}->{ident(f.name)}", add))

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


def c_converters(schema: Schema) -> tuple[list[CConverter], dict[str, str], list[str]]:
    """(the converters, their shared helper functions by name, the mappings left out with why)."""
    helpers: dict[str, list[str]] = {}
    endpoints = {e.name: e for s in schema.mappings for e in s.endpoints}
    made: list[CConverter] = []
    left: list[str] = []
    for mapping in (m for s in schema.mappings for m in s.mappings):
        if CONCEPTS_ENDPOINT in (mapping.source, mapping.target):
            left.append(f"{mapping.name} (through the concepts)")
            continue
        src, dst = endpoints[mapping.source], endpoints[mapping.target]
        if any(schema.message(q).format not in _FORMATS for q in (*src.messages, *dst.messages)):
            left.append(f"{mapping.name} (no C codec for {mapping.source} or {mapping.target})")
            continue
        saved = dict(helpers)
        b = _Builder(schema, mapping, src, dst, helpers)
        try:
            body = b.build()
        except Unsupported as e:
            helpers.clear()
            helpers.update(saved)
            left.append(f"{mapping.name} ({e})")
            continue
        made.append(
            CConverter(
                mapping,
                f"battgen_convert_{ident(mapping.name)}",
                [(q, b.var(src, q, "s"), i > 0) for i, q in enumerate(src.messages)],
                [(q, b.var(dst, q, "t")) for q in dst.messages],
                b.inputs,
                b.unused() + body,
                " ".join(mapping.doc.split()),
            )
        )
    return made, {k: "\n".join(v) for k, v in sorted(helpers.items())}, left
