"""The px4 ops as Rust: PX4's own C code (uavcan bridge, ...) rule by rule, in f32 arithmetic with
C's conversions (the C backend's ``convert_px4``, in Rust), as the Python backend's ``px4*.py``
writes them. Rust's f32 arithmetic rounds every step to f32, as PX4's does."""

from __future__ import annotations

import math

from ...ir import CONCEPTS_ENDPOINT, ArrayType, FieldRef, PrimitiveType, Rule, StringType, units
from ...ir import ops as o
from .convert_context import RustBase, cast, paren
from .convert_values import Unsupported, f32, f32_literal, literal
from .naming import field_ident
from .types import capacity, scalar

FLT_EPS = 1.1920928955078125e-07


class PX4Ops(RustBase):
    def visit_zero_all(self, rule: Rule, op: o.ZeroAll) -> None:
        for ref in rule.targets:
            var = self.var(self.dst, ref.message, "t")
            for f in self.schema.message(ref.message).fields:
                if f.invalid is None or f.is_padding:
                    continue
                t = f.type
                name = f"{var}.{field_ident(f.name)}"
                if isinstance(t, ArrayType):
                    if t.dynamic or not isinstance(t.element, PrimitiveType):
                        raise Unsupported("zeroing a dynamic array")
                    self.emit(f"{name} = [{literal(t.element, 0)}; {capacity(t)}];")
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
        for f in src_m.fields:
            g = dst_fields.get(f.name)
            if f.is_padding or g is None:
                continue
            src = self.s(FieldRef(src_m.qualified_name, f.name))
            dst = self.t(FieldRef(dst_m.qualified_name, g.name))
            if isinstance(f.type, PrimitiveType) and isinstance(g.type, PrimitiveType):
                a, b = scalar(f.type), scalar(g.type)
                if b == "bool" and a != "bool":
                    self.emit(f"{dst} = {src} != 0;")
                elif a == "bool" and b != "bool":
                    self.emit(f"{dst} = {b}::from({src});")
                else:
                    self.emit(f"{dst} = {cast(src, a, b)};")
            elif isinstance(f.type, ArrayType) and f.type == g.type and not f.type.dynamic:
                self.emit(f"{dst} = {src};")
            else:
                raise Unsupported(f"same_names: {f.name} changes its type")

    def text_const(self, ref: FieldRef, t: ArrayType | StringType, value: str) -> None:
        """A text constant into a byte array (its bytes, the rest zero) as Python writes the bytes."""
        data = value.encode("utf-8")
        cap = t.capacity or 0
        if len(data) > cap:
            raise Unsupported("a text constant longer than its field")
        target = self.t(ref)
        if isinstance(t, ArrayType) and t.dynamic:
            self.emit(f"{target}_len = {len(data)};")
        else:
            self.emit(f"{target} = [0; {capacity(t)}];")
        if data:
            self.emit(f"{target}[..{len(data)}].copy_from_slice(b{_bytes_literal(data)});")

    def visit_px4_convert(self, rule: Rule, op: o.PX4Convert) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        start = len(self.lines)
        self.emit(f"let mut x: f32 = {self.px4_read(src)};")
        if op.convert is o.PX4Conversion.UNITS:
            su = units.lookup(op.source_unit) if op.source_unit else self.fld(src).unit
            tu = units.lookup(op.target_unit) if op.target_unit else self.fld(dst).unit
            if su is None or tu is None:
                raise Unsupported("px4_convert without units")
            mul, add = su.factor_to(tu)
            if mul != 1.0:
                if op.form is o.PX4Form.DIVIDE:
                    self.emit(f"x /= {f32_literal(f32(1.0 / mul))};")
                else:
                    self.emit(f"x *= {f32_literal(f32(mul))};")
            if add != 0.0:
                self.emit(f"x += {f32_literal(f32(add))};")
        if op.round:
            self.emit("x = roundf(x);")
        if len(self.lines) == start + 1:  # x never changes
            self.lines[start] = self.lines[start].replace("let mut x", "let x")
        value = self.store_c(dst, "x")
        p = self.prim(dst)
        target = self.t(dst)
        if op.at_least is not None:  # max(value, at_least), the value converted only where it is stored
            k = literal(p, op.at_least)
            assign = [f"let y = {value};", f"{target} = if {k} > y {{ {k} }} else {{ y }};"]
        else:
            assign = [f"{target} = {value};"]
        tests = []
        if op.guard is not None:
            guard = FieldRef(src.message, op.guard)
            g = self.s(guard)
            tests.append(g if self.rust(guard) == "bool" else f"{g} != 0")
        if op.finite:
            tests.append("x.is_finite()")
        if op.above is not None:
            tests.append(f"x > {f32_literal(f32(float(op.above)))}")
        if not tests:
            self.emit(*assign)
            return
        otherwise = self.value_of(op.otherwise if op.otherwise is not None else 0, [dst])
        self.emit(
            f"if {' && '.join(tests)} {{",
            *assign,
            "} else {",
            f"{target} = {literal(p, otherwise)};",
            "}",
        )

    def visit_px4_int(self, rule: Rule, op: o.PX4Int) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        expr = self.int_source(src)
        if op.mask is not None:
            expr = f"{paren(expr)} & {self.mask(op.mask, [src])}"
        if op.add:
            expr = f"{paren(expr)} + {int(op.add)}"
        self.emit(f"{self.t(dst)} = {self.int_store(dst, expr)};")

    def visit_px4_warning(self, rule: Rule, op: o.PX4Warning) -> None:
        dst = rule.targets[0]
        level = self.t(FieldRef(dst.message, op.of))
        target = self.t(dst)
        p = self.prim(dst)
        self.emit(f"let s: f32 = {level};")
        chain = (
            ("if", "emergency", op.emergency),
            ("} else if", "critical", op.critical),
            ("} else if", "low", op.low),
        )
        for keyword, name, threshold in chain:
            value = self.constant_value(f"WARNING_{name.upper()}", [dst])
            self.emit(f"{keyword} s < {f32_literal(f32(float(threshold)))} {{", f"{target} = {literal(p, value)};")
        none = self.constant_value("WARNING_NONE", [dst])
        self.emit("} else {", f"{target} = {literal(p, none)};", "}")

    def visit_enum_map(self, rule: Rule, op: o.EnumMap) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        p = self.prim(dst)
        default = self.value_of(op.default if op.default is not None else 0, [dst])
        self.emit(f"{self.t(dst)} = match {self.int_source(src)} {{")
        seen: set[object] = set()
        for pair in op.map:
            key = self.value_of(pair.source, [src])
            if not isinstance(key, int):
                raise Unsupported(f"the key {key!r}")
            if key in seen:  # Python's dict keeps the last; none of the mappings repeats a key
                raise Unsupported("a repeated key")
            seen.add(key)
            self.emit(f"{key} => {literal(p, self.value_of(pair.target, [dst]))},")
        self.emit(f"_ => {literal(p, default)},", "};")

    def visit_bits_from(self, rule: Rule, op: o.BitsFrom) -> None:
        dst = rule.targets[0]
        self.emit("let mut b = 0_u64;")
        for bit in op.bits:
            src = FieldRef(rule.sources[0].message, bit.field)
            value = self.s(src)
            cond = value if self.rust(src) == "bool" else f"{value} != 0"
            if bit.equals is not None:
                cond = f"{value} == {literal(self.prim(src), self.value_of(bit.equals, [src]))}"
            self.emit(f"if {cond} {{ b |= {self.mask(bit.mask, [dst])}; }}")
        self.emit(f"{self.t(dst)} = {self.int_store(dst, 'b as i64')};")

    def visit_px4_bridge_cells(self, rule: Rule, op: o.PX4BridgeCells) -> None:
        volt, aux_cells = rule.sources
        cells, count = rule.targets
        t = self.fld(cells).type
        assert isinstance(t, ArrayType)
        cap = t.capacity or 0
        aux = self.var(self.src, aux_cells.message, "s")
        target = self.t(cells)
        crust = self.rust(count)
        self.emit(
            f"{target} = [0.0; {capacity(t)}];",
            f"{target}[0] = {self.px4_read(volt)};",
            f"match {aux} {{",
            f"None => {self.t(count)} = 1,",
            f"Some({aux}) => {{",
            f"let n = ({self.s(aux_cells)}_len & 0xFF).min({cap});",
            "for i in 0..n {",
            f"{target}[i] = {self.px4_read(aux_cells, f'{self.s(aux_cells)}[i]')};",
            "}",
            f"{self.t(count)} = {cast('n', 'usize', crust)};",
            "}",
            "}",
        )

    def visit_px4_aux_capacity(self, rule: Rule, op: o.PX4AuxCapacity) -> None:
        energy, voltage = rule.sources
        dst = rule.targets[0]
        ah = units.lookup("Ah")
        unit = self.fld(dst).unit
        mul = ah.factor_to(unit)[0] if ah is not None and unit is not None else 1.0
        eps = f32(float(op.above if op.above is not None else FLT_EPS))
        value = f"{self.px4_read(energy)} * {f32_literal(f32(mul))} / v"
        self.emit(
            f"let v: f32 = {self.px4_read(voltage)};",
            f"if v > {f32_literal(eps)} {{",
            f"{self.t(dst)} = {self.store_c(dst, value)};",
            "}",
        )

    def visit_px4_bridge_estimates(self, rule: Rule, op: o.PX4BridgeEstimates) -> None:
        current, aux = rule.sources
        discharged, remaining_time, average = rule.targets
        dt, total = field_ident(op.dt_input), field_ident(op.discharged_input)
        for name in (dt, total):
            if name not in self.inputs:
                self.inputs.append(name)
        soc = self.t(FieldRef(discharged.message, op.soc_of))
        capacity_ = self.t(FieldRef(discharged.message, op.capacity_of))
        eps = f32_literal(FLT_EPS)
        cap_rust = self.rust(FieldRef(discharged.message, op.capacity_of))
        cap_value = f"f32::from({capacity_})" if cap_rust in ("u8", "u16", "i8", "i16") else f"({capacity_} as f32)"
        if cap_rust == "f32":
            cap_value = capacity_
        self.emit(
            f"let mut v: f32 = {total}.unwrap_or(0.0);",
            f"if {self.var(self.src, aux.message, 's')}.is_none() {{",
            "// Battery::updateDt (at most 2 s) and Battery::sumDischarged(fabsf(msg.current))",
            f"let x = absf({self.px4_read(current)});",
            f"let t = {dt}.map_or(0.0, |d| if 2.0 < d {{ 2.0 }} else {{ d }});",
            f"if t > {eps} {{",
            "v += x * 1000.0 * (t / 3600.0);",
            "}",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "} else {",
            "// Battery::computeRemainingTime while disarmed: the average filter reset to BAT_AVRG_CURRENT",
            f"let m: f32 = {f32_literal(f32(float(op.average_current)))};",
            f"{self.t(average)} = m;",
            f"let cap: f32 = {cap_value};",
            f"let s: f32 = {soc};",
            f"{self.t(remaining_time)} = {f32_literal(math.nan)};",
            "if cap > 0.0 {",
            "let d = m * 1000.0;",
            f"let d = if {eps} > d {{ {eps} }} else {{ d }};",
            f"{self.t(remaining_time)} = s * cap / d * 3600.0;",
            "}",
            "}",
            f"{self.t(discharged)} = v;",
        )


def _bytes_literal(data: bytes) -> str:
    return '"' + "".join(chr(b) if 0x20 <= b < 0x7F and chr(b) not in '"\\' else f"\\x{b:02x}" for b in data) + '"'
