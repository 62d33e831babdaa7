"""Emitters of the ops that follow PX4's own C code (px4 mappings): numbers and enumerations.

Values are read as PX4 holds them (C floats; DroneCAN float16 as received), computed in float32
(every constant rounded to float32 first) and stored with C's conversions, so a converter gives
the bytes PX4 would send.
"""

from __future__ import annotations

import math

from ....errors import BattgenError
from ....ir import FieldRef, PrimitiveKind, Rule, units
from ....ir.ops import (
    BitsFrom,
    EnumMap,
    PX4AuxCapacity,
    PX4BridgeEstimates,
    PX4Conversion,
    PX4Convert,
    PX4Form,
    PX4Int,
    PX4UdralEnergy,
    PX4Warning,
)
from .. import naming
from ..literals import float_literal, py_literal
from .context import FLT_EPS, RuleContext, call, constant_name, f32, factor


class PX4Emitters(RuleContext):
    def visit_px4_convert(self, rule: Rule, op: PX4Convert) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        f_dst = self.fld(dst)
        label = self.label(dst)
        self.emit(f"_x = {self.px4_read(src)}")
        if op.convert is PX4Conversion.UNITS:
            su = self.unit_param(op.source_unit, self.fld(src).unit)
            tu = self.unit_param(op.target_unit, f_dst.unit)
            if su is None or tu is None:
                raise BattgenError(f"{self.mapping.name}: {src.field} -> {dst.field} needs units on both sides")
            mul, add = su.factor_to(tu)
            if mul != 1.0:
                if op.form is PX4Form.DIVIDE:
                    self.emit(f"_x = _r.f32(_x / {float_literal(f32(1.0 / mul))})")
                else:
                    self.emit(f"_x = _r.f32(_x * {float_literal(f32(mul))})")
            if add != 0.0:
                self.emit(f"_x = _r.f32(_x + {float_literal(f32(add))})")
        if op.round:
            self.emit("_x = _r.roundf(_x)")
        value = self.store_c(f_dst, "_x", label)
        if op.at_least is not None:
            value = call("max", [value, py_literal(op.at_least)])
        tests = []
        if op.guard is not None:
            tests.append(self.s(FieldRef(src.message, op.guard)))
        if op.finite:
            tests.append("_math.isfinite(_x)")
        if op.above is not None:
            tests.append(f"_x > {float_literal(f32(float(op.above)))}")
        target = self.t(dst)
        if not tests:
            self.emit_assign(target, value)
            return
        otherwise = self.value_of(op.otherwise if op.otherwise is not None else 0, [dst])
        self.emit(f"if {' and '.join(tests)}:")
        self.emit_assign(target, value, 1)
        self.emit("else:", f"    {target} = {py_literal(otherwise)}")

    def visit_px4_int(self, rule: Rule, op: PX4Int) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        expr = f"int({self.s(src)})"
        if op.mask is not None:
            expr = f"({expr} & {py_literal(self.mask(op.mask, [src]))})"
        if op.add:
            expr = f"{expr} - {py_literal(-op.add)}" if op.add < 0 else f"{expr} + {py_literal(op.add)}"
        prim = self.prim(self.fld(dst))
        if prim is None:
            raise BattgenError(f"{self.mapping.name}: {dst.field} is not a number")
        if prim.kind is PrimitiveKind.BOOL:
            self.emit(f"{self.t(dst)} = bool({expr})")
            return
        storage = next(b for b in (8, 16, 32, 64) if b >= prim.bits)
        value = call("_r.c_wrap", [expr, str(storage), str(prim.kind is PrimitiveKind.INT)])
        if storage != prim.bits:
            lo, hi = prim.value_range or (0, 0)
            value = call("_r.saturate", [value, str(int(lo)), str(int(hi))])
        self.emit_assign(self.t(dst), value)

    def visit_px4_warning(self, rule: Rule, op: PX4Warning) -> None:
        dst = rule.targets[0]
        level = self.t(FieldRef(dst.message, op.of))
        target = self.t(dst)
        self.emit(f"_s = {level}")
        chain = (("if", "emergency", op.emergency), ("elif", "critical", op.critical), ("elif", "low", op.low))
        for keyword, name, threshold in chain:
            value = self.constant_value(f"WARNING_{name.upper()}", [dst])
            self.emit(f"{keyword} _s < {float_literal(f32(float(threshold)))}:", f"    {target} = {py_literal(value)}")
        self.emit("else:", f"    {target} = {py_literal(self.constant_value('WARNING_NONE', [dst]))}")

    def visit_enum_map(self, rule: Rule, op: EnumMap) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        table = {self.value_of(pair.source, [src]): self.value_of(pair.target, [dst]) for pair in op.map}
        default = self.value_of(op.default if op.default is not None else 0, [dst])
        by_value = self.const(constant_name(dst.field, "by", src.field), table)
        self.emit(f"{self.t(dst)} = {by_value}.get({self.s(src)}, {py_literal(default)})")

    def visit_bits_from(self, rule: Rule, op: BitsFrom) -> None:
        dst = rule.targets[0]
        self.emit("_b = 0")
        for bit in op.bits:
            src = FieldRef(rule.sources[0].message, bit.field)
            cond = self.s(src)
            if bit.equals is not None:
                cond = f"{cond} == {py_literal(self.value_of(bit.equals, [src]))}"
            self.emit(f"if {cond}:", f"    _b |= {py_literal(self.mask(bit.mask, [dst]))}")
        self.emit(f"{self.t(dst)} = _b")

    def visit_px4_aux_capacity(self, rule: Rule, op: PX4AuxCapacity) -> None:
        energy, voltage = rule.sources
        dst = rule.targets[0]
        f_dst = self.fld(dst)
        # Wh / V is Ah; the factor to the target's unit (mAh) comes from the unit registry
        mul, _ = factor(units.lookup("Ah"), f_dst.unit)
        eps = f32(float(op.above if op.above is not None else FLT_EPS))
        value = f"_r.f32(_r.f32({self.px4_read(energy)} * {float_literal(f32(mul))}) / _v)"
        self.emit(f"_v = {self.px4_read(voltage)}", f"if _v > {float_literal(eps)}:")
        self.emit_assign(self.t(dst), self.store_c(f_dst, value, self.label(dst)), 1)

    def visit_px4_udral_energy(self, rule: Rule, op: PX4UdralEnergy) -> None:
        """Runs without the Parameters message too (``HANDLES_MISSING``): the nominal voltage is NaN then."""
        energy, full, nominal = rule.sources
        remaining, discharged = rule.targets
        nominal_read = self.px4_read(nominal)
        if self.src.optional(nominal.message):
            nominal_read = f"{float_literal(math.nan)} if {self.src.var(nominal.message)} is None else {nominal_read}"
        self.emit(f"_e = {self.px4_read(energy)}", f"_f = {self.px4_read(full)}", f"_n = {nominal_read}")
        ratio = self.store_c(self.fld(remaining), "_r.f32_div(_e, _f)", self.label(remaining))
        self.emit_assign(self.t(remaining), ratio)
        # (full - energy) / (nominal * WH_TO_JOULE): ampere-hours, into a field PX4 counts in mAh
        spent = "_r.f32_div(_r.f32(_f - _e), _r.f32(_n * 3600.0))"
        self.emit_assign(self.t(discharged), self.store_c(self.fld(discharged), spent, self.label(discharged)))

    def visit_px4_bridge_estimates(self, rule: Rule, op: PX4BridgeEstimates) -> None:
        """Runs without the companion message too (``HANDLES_MISSING``): PX4's raw mode."""
        current, aux = rule.sources
        discharged, remaining_time, average = rule.targets
        dt, total = naming.identifier(op.dt_input), naming.identifier(op.discharged_input)
        for name in (dt, total):
            if name not in self.inputs:
                self.inputs.append(name)
        soc = self.t(FieldRef(discharged.message, op.soc_of))
        capacity = self.t(FieldRef(discharged.message, op.capacity_of))
        eps = float_literal(FLT_EPS)
        self.emit(
            f"_v = 0.0 if {total} is None else _r.f32({total})",
            f"if {self.src.var(aux.message)} is None:",
            "    # Battery::updateDt (at most 2 s) and Battery::sumDischarged(fabsf(msg.current))",
            f"    _x = abs({self.px4_read(current)})",
            f"    _t = 0.0 if {dt} is None else _r.f32(min(_r.f32({dt}), 2.0))",
            f"    if _t > {eps}:",
            "        _v = _r.f32(_v + _r.f32(_r.f32(_x * 1000.0) * _r.f32(_t / 3600.0)))",
            f"    {self.t(remaining_time)} = {float_literal(math.nan)}",
            "else:",
            "    # Battery::computeRemainingTime while disarmed: the average filter reset to BAT_AVRG_CURRENT",
            f"    _m = {float_literal(f32(float(op.average_current)))}",
            f"    {self.t(average)} = _m",
            f"    _cap = _r.f32({capacity})",
            f"    _s = {soc}",
            f"    {self.t(remaining_time)} = {float_literal(math.nan)}",
            "    if _cap > 0:",
            f"        _x = _r.f32(_r.f32(_s * _cap) / max(_r.f32(_m * 1000.0), {eps}))",
            f"        {self.t(remaining_time)} = _r.f32(_x * 3600.0)",
            f"{self.t(discharged)} = _v",
        )
