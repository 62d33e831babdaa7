"""Emitters of the ops that follow PX4's own C code for cell voltages, one per PX4 code path:
the MAVLink stream and receiver, the uavcan bridge and the uavcannode publisher."""

from __future__ import annotations

from ....ir import Rule
from ....ir.ops import PX4BridgeCells, PX4CellList, PX4ReceiverCells, PX4StreamCells
from ..literals import float_literal
from .context import RuleContext, array_type, f32, factor


class PX4CellEmitters(RuleContext):
    def visit_px4_stream_cells(self, rule: Rule, op: PX4StreamCells) -> None:
        volt, cells, count, connected = rule.sources
        main, ext = rule.targets
        mf, ef = self.fld(main), self.fld(ext)
        mul, _ = factor(self.fld(cells).unit, mf.unit)
        fill = int(mf.invalid.value) if mf.invalid is not None else 0xFFFF
        threshold = f32(float(op.cell_threshold if op.cell_threshold is not None else 0.0001))
        numbers = [float_literal(f32(mul)), float_literal(threshold)]
        args = [self.s(volt), self.s(cells), self.s(count), self.s(connected), *numbers]
        sizes = [str(array_type(mf).capacity), str(array_type(ef).capacity), str(fill), "0"]
        self.emit_call(
            f"{self.t(main)}, {self.t(ext)} = _cells.px4_stream_cells", [*args, *sizes, "rep", self.label(main)]
        )

    def visit_px4_receiver_cells(self, rule: Rule, op: PX4ReceiverCells) -> None:
        (volts,) = rule.sources
        cells, count, total = rule.targets
        vf, cf = self.fld(volts), self.fld(cells)
        mul, _ = factor(vf.unit, cf.unit)
        mark = int(vf.invalid.value) if vf.invalid is not None else 0xFFFF
        args = [self.s(volts), str(array_type(cf).capacity), str(mark), float_literal(f32(1.0 / mul))]
        self.emit_call("_c, _n, _t = _cells.px4_receiver_cells", args)
        self.emit(f"{self.t(cells)} = _c", f"{self.t(count)} = _n", f"{self.t(total)} = _t")

    def visit_px4_bridge_cells(self, rule: Rule, op: PX4BridgeCells) -> None:
        """Runs without the companion message too (``HANDLES_MISSING``): one cell, the pack voltage."""
        volt, aux_cells = rule.sources
        cells, count = rule.targets
        cap = array_type(self.fld(cells)).capacity
        aux_var = self.src.var(aux_cells.message)
        target = self.t(cells)
        self.emit(
            f"_c = [0.0] * {cap}",
            f"_c[0] = {self.px4_read(volt)}",
            f"if {aux_var} is None:",
            f"    {self.t(count)} = 1",
            "else:",
            f"    _a = {self.s(aux_cells)}",
            f"    _n = min(len(_a) & 0xFF, {cap})",
            "    for _i in range(_n):",
            f"        _c[_i] = {self.px4_read(aux_cells, '_a[_i]')}",
            f"    {self.t(count)} = _n",
            f"{target} = _c",
        )

    def visit_px4_cell_list(self, rule: Rule, op: PX4CellList) -> None:
        cells, count = rule.sources
        dst = rule.targets[0]
        cap = array_type(self.fld(cells)).capacity
        label = self.label(dst)
        source = self.s(cells)
        target = self.t(dst)
        self.emit(f"_n = {self.s(count)}", f"if _n > {cap} and rep is not None:")
        self.emit_call("rep.clamped", [label, f'f"{{int(_n)}} cells, {cap} in the array"'], 1)
        self.emit(f"_m = min(_n, {cap})")
        self.emit_with_label(
            lambda name: f"{target} = [{self.store_c(self.fld(dst), '_r.f32(_x)', name)} for _x in {source}[:_m]]",
            label,
        )
