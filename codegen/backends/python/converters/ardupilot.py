"""Emitters of the ops that follow ArduPilot's own code (the ``ardupilot`` policy): its DroneCAN battery
monitor and BATTERY_STATUS sender. The arithmetic lives in the runtime module ``_ardupilot``
(``runtime/convert/_ardupilot.py``); an emitter reads the fields as the firmware holds them (a DroneCAN
float16 as received, :meth:`~.context.RuleContext.px4_read`) and names the converter inputs.
"""

from __future__ import annotations

from ....ir import FieldRef, Rule
from ....ir.ops import ArduPilotCells, ArduPilotCurrent, ArduPilotEstimates, ArduPilotTemperature
from .. import naming
from ..literals import float_literal, py_literal
from .context import RuleContext, array_type, call, f32

_INT16_MAX = 0x7FFF


class ArduPilotEmitters(RuleContext):
    def _input(self, name: str) -> str:
        ident = naming.identifier(name)
        if ident not in self.inputs:
            self.inputs.append(ident)
        return ident

    def _amps(self, current: FieldRef, curr_mult_input: str) -> str:
        mult = self._input(curr_mult_input)
        return f"_r.f32(_r.f32(1.0 if {mult} is None else {mult}) * {self.px4_read(current)})"

    def visit_ardupilot_temperature(self, rule: Rule, op: ArduPilotTemperature) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        kelvin = float_literal(f32(273.15))
        centi = self.store_c(self.fld(dst), f"_r.f32(_r.f32(_x - {kelvin}) * 100.0)", self.label(dst))
        self.emit(f"_x = {self.px4_read(src)}", "if _x > 0.0:  # NaN > 0 is false: no temperature")
        self.emit_assign(self.t(dst), centi, 1)
        self.emit("else:", f"    {self.t(dst)} = {_INT16_MAX}")

    def visit_ardupilot_current(self, rule: Rule, op: ArduPilotCurrent) -> None:
        src, dst = rule.sources[0], rule.targets[0]
        bound = float_literal(float(_INT16_MAX))
        self.emit(f"_a = {self._amps(src, op.curr_mult_input)}")
        self.emit("if rep is not None and _a != _a:")
        self.emit_call("rep.unrepresentable", [self.label(dst), '"NaN current, sent as 0 (AP_Math constrain)"'], 1)
        centi = call("_ap.constrain", [call("_r.f32", ["_a * 100.0"]), f"-{bound}", bound])
        self.emit_assign(self.t(dst), self.store_c(self.fld(dst), centi, self.label(dst)))

    def visit_ardupilot_cells(self, rule: Rule, op: ArduPilotCells) -> None:
        """Runs without the companion message too (``HANDLES_MISSING``): the pack voltage in the cells."""
        volt, aux_cells = rule.sources
        main, ext = rule.targets
        aux_var = self.src.var(aux_cells.message)
        sizes = [str(int(op.max_cells)), *(str(array_type(self.fld(t)).capacity) for t in (main, ext))]
        cells = f"[{self.px4_read(aux_cells, '_v')} for _v in {self.s(aux_cells)}]"
        self.emit(f"_c = None if {aux_var} is None else {cells}")
        args = [self.px4_read(volt), "_c", *sizes, "rep", self.label(main)]
        self.emit_call(f"{self.t(main)}, {self.t(ext)} = _ap.ardupilot_cells", args)

    def visit_ardupilot_estimates(self, rule: Rule, op: ArduPilotEstimates) -> None:
        """Runs without the companion message too (``HANDLES_MISSING``): no nominal voltage then."""
        voltage, current, soc, remaining, full, nominal = rule.sources
        aux_var = self.src.var(nominal.message)
        capacity = self._input(op.capacity_input)
        inputs = [
            self._input(op.dt_input),
            self._input(op.consumed_input),
            self._input(op.energy_input),
            f"{py_literal(op.capacity_default)} if {capacity} is None else {capacity}",
            self._input(op.options_input),
            self._input(op.curr_mult_input),
        ]
        self.emit(
            f"_n = None if {aux_var} is None else {self.px4_read(nominal)}",
            f"_i = ({', '.join(inputs)})",
        )
        reads = [self.px4_read(r) for r in (voltage, current)] + [f"int({self.s(soc)})"]
        reads += [self.px4_read(r) for r in (remaining, full)]
        labels = f"({', '.join(self.label(t) for t in rule.targets)})"
        self.emit_call("_e = _ap.ardupilot_estimates", [*reads, "_n", "_i", "rep", labels])
        for i, target in enumerate(rule.targets):
            self.emit(f"{self.t(target)} = _e[{i}]")
