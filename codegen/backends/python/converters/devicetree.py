"""Emitters of the ops reading devicetree battery facts: dt_pack, ocv_soc."""

from __future__ import annotations

from ....ir import Rule, units
from ....ir.ops import DtPack, OcvSoc
from .. import naming
from ..literals import float_literal, py_literal
from .context import RuleContext, constant_name, factor


class DevicetreeEmitters(RuleContext):
    def visit_dt_pack(self, rule: Rule, op: DtPack) -> None:
        vmax, vmin, chem = rule.sources
        count, nominal = rule.targets
        charged, empty, cell_nominal = (
            self.const(constant_name(name), {e.chemistry: e.volts for e in table})
            for name, table in (
                ("cell_charged_v", op.cell_charged_v),
                ("cell_empty_v", op.cell_empty_v),
                ("cell_nominal_v", op.cell_nominal_v),
            )
        )
        mul_max, _ = factor(self.fld(vmax).unit, units.lookup("V"))
        mul_min, _ = factor(self.fld(vmin).unit, units.lookup("V"))
        self.emit(
            f"_hi = _cells.dt_first({self.s(vmax)})",
            f"_lo = _cells.dt_first({self.s(vmin)})",
            f"_ch = {self.s(chem)}",
        )
        args = [
            f"None if _hi is None else _hi * {float_literal(mul_max)}",
            f"None if _lo is None else _lo * {float_literal(mul_min)}",
            "_ch",
            charged,
            empty,
        ]
        self.emit_call("_n = _cells.cells_from_design", list(args))
        self.emit(
            "if _n is not None:",
            f"    {self.t(count)} = _n",
            f"    if _ch is not None and _ch in {cell_nominal}:",
            f"        {self.t(nominal)} = _n * {cell_nominal}[_ch]",
        )

    def visit_ocv_soc(self, rule: Rule, op: OcvSoc) -> None:
        temps, tables = rule.sources
        voltage, temperature = naming.identifier(op.voltage_input), naming.identifier(op.temperature_input)
        for name in (voltage, temperature):
            if name not in self.inputs:
                self.inputs.append(name)
        to_uv, _ = factor(units.lookup("V"), units.lookup("uV"))
        pct, _ = factor(units.lookup("%"), self.concepts[rule.targets[0].field].unit)
        tf = self.fld(tables)
        stem = (tf.pattern or tf.name).strip("^$").split("[", 1)[0]
        self.emit(
            f"_ts = {self.s(temps)}",
            f"_tb = {self.s(tables)}",
            f"if {voltage} is not None and _ts:",
            f"    _tabs = [_x for _x in (_tb.get({py_literal(stem)} + str(_i)) for _i in range(len(_ts))) if _x]",
            f"    _t = {temperature}",
            "    if _t is None and len(_ts) == 1:",
            "        _t = _ts[0]",
            "    if _t is not None and len(_tabs) == len(_ts):",
            f"        _uv = round({voltage} * {float_literal(to_uv)})",
            "        _cap = _cells.ocv_to_capacity(_tabs, _ts, _uv, round(_t))",
            f"        {self.t(rule.targets[0])} = _cap * {float_literal(pct)}",
        )
