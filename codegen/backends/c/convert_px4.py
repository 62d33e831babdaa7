"""The px4 ops as C: PX4's own C code (uavcan bridge, ...) rule by rule, in float32 arithmetic with
C's conversions, as ``codegen/backends/python/converters/px4*.py`` writes them in Python."""

from __future__ import annotations

import math

from ...ir import CONCEPTS_ENDPOINT, ArrayType, FieldRef, PrimitiveKind, PrimitiveType, Rule, StringType, units
from ...ir import ops as o
from .convert_context import CBase
from .convert_values import Unsupported, f32, f32_literal, literal
from .types import ident, scalar

FLT_EPS = 1.1920928955078125e-07


class PX4Ops(CBase):
    """Every float32 operation is cast (or assigned) to float: a compiler evaluating float
    expressions in double (FLT_EVAL_METHOD 1, s390x's gcc) then rounds each step as PX4's does."""

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
            if ref.message == CONCEPTS_ENDPOINT:
                self.concept_const(ref, value)
                continue
            t = self.fld(ref).type
            if isinstance(value, str) and isinstance(t, ArrayType | StringType):
                self.text_const(ref, t, value)
                continue
            if not isinstance(t, PrimitiveType):
                raise Unsupported("a constant into an array")
            self.emit(f"{self.t(ref)} = {literal(self.prim(ref), value)};")

    def visit_same_names(self, rule: Rule, op: o.SameNames) -> None:
        """uORB versions: every field of the same name copied as it is."""
        src_m = self.schema.message(rule.sources[0].message)
        dst_m = self.schema.message(rule.targets[0].message)
        dst_fields = {f.name: f for f in dst_m.fields}
        loops = False
        lines: list[str] = []
        for f in src_m.fields:
            g = dst_fields.get(f.name)
            if f.is_padding or g is None:
                continue
            src = self.s(FieldRef(src_m.qualified_name, f.name))
            dst = self.t(FieldRef(dst_m.qualified_name, g.name))
            if isinstance(f.type, PrimitiveType) and isinstance(g.type, PrimitiveType):
                lines.append(f"{dst} = ({scalar(g.type)}){src};")
            elif isinstance(f.type, ArrayType) and f.type == g.type and not f.type.dynamic:
                loops = True
                lines.append(f"for (i = 0; i < {f.type.capacity or 0}u; i++) {{ {dst}[i] = {src}[i]; }}")
            else:
                raise Unsupported(f"same_names: {f.name} changes its type")
        self.emit(*(["size_t i;"] if loops else []), *lines)

    def text_const(self, ref: FieldRef, t: ArrayType | StringType, value: str) -> None:
        """A text constant into a byte array (its bytes, the rest zero) as Python writes the bytes."""
        data = value.encode("utf-8")
        cap = t.capacity or 0
        if len(data) > cap:
            raise Unsupported("a text constant longer than its field")
        target = self.t(ref)
        cast = "(char)" if isinstance(t, StringType) or getattr(t.element, "kind", None) is PrimitiveKind.CHAR else ""
        if isinstance(t, ArrayType) and t.dynamic:
            self.emit(f"{target}_len = {len(data)}u;")
        else:
            self.emit(f"battgen_zero({target}, sizeof {target});")
        self.emit(*(f"{target}[{i}] = {cast}{b}u;" for i, b in enumerate(data)))

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
                    self.emit(f"x = x / {f32_literal(f32(1.0 / mul))};")
                else:
                    self.emit(f"x = x * {f32_literal(f32(mul))};")
            if add != 0.0:
                self.emit(f"x = x + {f32_literal(f32(add))};")
        if op.round:
            self.emit("x = battgen_roundf(x);")
        value = self.store_c(dst, "x")
        p = self.prim(dst)
        stored = [f"{{ {scalar(p)} y = {value};", "", "}"] if op.at_least is not None else None
        if op.at_least is not None:  # max(value, at_least), the value converted only where it is stored
            k = literal(p, op.at_least)
            value = f"({k} > y ? {k} : y)"
        tests = []
        if op.guard is not None:
            tests.append(f"({self.s(FieldRef(src.message, op.guard))} != 0)")
        if op.finite:
            tests.append("!battgen_f32_is_nan(x) && !battgen_f32_is_inf(x)")
        if op.above is not None:
            tests.append(f"x > {f32_literal(f32(float(op.above)))}")
        target = self.t(dst)
        assign = [f"{target} = {value};"]
        if stored is not None:
            assign = [stored[0], *assign, stored[2]]
        if not tests:
            self.emit(*assign)
            return
        otherwise = self.value_of(op.otherwise if op.otherwise is not None else 0, [dst])
        self.emit(
            f"if ({' && '.join(tests)}) {{",
            *assign,
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
            self.emit(f"{keyword} (s < {f32_literal(f32(float(threshold)))}) {{", f"{target} = {literal(p, value)};")
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
        eps = f32(float(op.above if op.above is not None else FLT_EPS))
        value = f"(float)((float)({self.px4_read(energy)} * {f32_literal(f32(mul))}) / v)"
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
            "v = v + (float)((float)(x * 1000.0f) * (float)(t / 3600.0f));",
            "}",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "} else {",
            "/* Battery::computeRemainingTime while disarmed: the average filter reset to BAT_AVRG_CURRENT */",
            f"float m = {f32_literal(f32(float(op.average_current)))};",
            "float cap, s, d;",
            f"{self.t(average)} = m;",
            f"cap = (float){capacity};",
            f"s = {soc};",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "if (cap > 0.0f) {",
            "d = m * 1000.0f;",
            f"d = {eps} > d ? {eps} : d;",
            f"{self.t(remaining_time)} = (float)((float)((float)(s * cap) / d) * 3600.0f);",
            "}",
            "}",
            f"{self.t(discharged)} = v;",
        )
