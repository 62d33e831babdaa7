"""The contract a backend implements to handle mapping rules: one method per op.

A backend writes a class with a ``visit_<op name>`` method for every op of :mod:`.ops` and lists
:class:`OpVisitor` among its bases; mypy then names any op it lacks (the class cannot be
instantiated). :func:`visit` hands a rule to the method for its op.
"""

from __future__ import annotations

from typing import Protocol, TypeVar, assert_never

from . import ops
from .mappings import Rule

T_co = TypeVar("T_co", covariant=True)


class OpVisitor(Protocol[T_co]):
    """Handles each mapping op; ``rule`` gives the references and location, ``op`` the parameters."""

    def visit_scale(self, rule: Rule, op: ops.Scale) -> T_co: ...
    def visit_copy(self, rule: Rule, op: ops.Copy) -> T_co: ...
    def visit_const(self, rule: Rule, op: ops.Const) -> T_co: ...
    def visit_soc_hybrid(self, rule: Rule, op: ops.SocHybrid) -> T_co: ...
    def visit_flag(self, rule: Rule, op: ops.Flag) -> T_co: ...
    def visit_flag_choice(self, rule: Rule, op: ops.FlagChoice) -> T_co: ...
    def visit_flags(self, rule: Rule, op: ops.Flags) -> T_co: ...
    def visit_choice(self, rule: Rule, op: ops.Choice) -> T_co: ...
    def visit_value_flags(self, rule: Rule, op: ops.ValueFlags) -> T_co: ...
    def visit_cells(self, rule: Rule, op: ops.Cells) -> T_co: ...
    def visit_mavlink_voltages(self, rule: Rule, op: ops.MavlinkVoltages) -> T_co: ...
    def visit_dt_pack(self, rule: Rule, op: ops.DtPack) -> T_co: ...
    def visit_ocv_soc(self, rule: Rule, op: ops.OcvSoc) -> T_co: ...
    def visit_same_names(self, rule: Rule, op: ops.SameNames) -> T_co: ...
    def visit_zero_all(self, rule: Rule, op: ops.ZeroAll) -> T_co: ...
    def visit_px4_convert(self, rule: Rule, op: ops.PX4Convert) -> T_co: ...
    def visit_px4_int(self, rule: Rule, op: ops.PX4Int) -> T_co: ...
    def visit_px4_warning(self, rule: Rule, op: ops.PX4Warning) -> T_co: ...
    def visit_enum_map(self, rule: Rule, op: ops.EnumMap) -> T_co: ...
    def visit_bits_from(self, rule: Rule, op: ops.BitsFrom) -> T_co: ...
    def visit_px4_stream_cells(self, rule: Rule, op: ops.PX4StreamCells) -> T_co: ...
    def visit_px4_receiver_cells(self, rule: Rule, op: ops.PX4ReceiverCells) -> T_co: ...
    def visit_px4_bridge_cells(self, rule: Rule, op: ops.PX4BridgeCells) -> T_co: ...
    def visit_px4_cell_list(self, rule: Rule, op: ops.PX4CellList) -> T_co: ...
    def visit_px4_aux_capacity(self, rule: Rule, op: ops.PX4AuxCapacity) -> T_co: ...
    def visit_px4_bridge_estimates(self, rule: Rule, op: ops.PX4BridgeEstimates) -> T_co: ...
    def visit_px4_udral_energy(self, rule: Rule, op: ops.PX4UdralEnergy) -> T_co: ...
    def visit_ardupilot_temperature(self, rule: Rule, op: ops.ArduPilotTemperature) -> T_co: ...
    def visit_ardupilot_current(self, rule: Rule, op: ops.ArduPilotCurrent) -> T_co: ...
    def visit_ardupilot_cells(self, rule: Rule, op: ops.ArduPilotCells) -> T_co: ...
    def visit_ardupilot_estimates(self, rule: Rule, op: ops.ArduPilotEstimates) -> T_co: ...


def visit(rule: Rule, visitor: OpVisitor[T_co]) -> T_co:
    """Call the visitor's method for the rule's op."""
    op = rule.op
    match op:
        case ops.Scale():
            return visitor.visit_scale(rule, op)
        case ops.Copy():
            return visitor.visit_copy(rule, op)
        case ops.Const():
            return visitor.visit_const(rule, op)
        case ops.SocHybrid():
            return visitor.visit_soc_hybrid(rule, op)
        case ops.Flag():
            return visitor.visit_flag(rule, op)
        case ops.FlagChoice():
            return visitor.visit_flag_choice(rule, op)
        case ops.Flags():
            return visitor.visit_flags(rule, op)
        case ops.Choice():
            return visitor.visit_choice(rule, op)
        case ops.ValueFlags():
            return visitor.visit_value_flags(rule, op)
        case ops.Cells():
            return visitor.visit_cells(rule, op)
        case ops.MavlinkVoltages():
            return visitor.visit_mavlink_voltages(rule, op)
        case ops.DtPack():
            return visitor.visit_dt_pack(rule, op)
        case ops.OcvSoc():
            return visitor.visit_ocv_soc(rule, op)
        case ops.SameNames():
            return visitor.visit_same_names(rule, op)
        case ops.ZeroAll():
            return visitor.visit_zero_all(rule, op)
        case ops.PX4Convert():
            return visitor.visit_px4_convert(rule, op)
        case ops.PX4Int():
            return visitor.visit_px4_int(rule, op)
        case ops.PX4Warning():
            return visitor.visit_px4_warning(rule, op)
        case ops.EnumMap():
            return visitor.visit_enum_map(rule, op)
        case ops.BitsFrom():
            return visitor.visit_bits_from(rule, op)
        case ops.PX4StreamCells():
            return visitor.visit_px4_stream_cells(rule, op)
        case ops.PX4ReceiverCells():
            return visitor.visit_px4_receiver_cells(rule, op)
        case ops.PX4BridgeCells():
            return visitor.visit_px4_bridge_cells(rule, op)
        case ops.PX4CellList():
            return visitor.visit_px4_cell_list(rule, op)
        case ops.PX4AuxCapacity():
            return visitor.visit_px4_aux_capacity(rule, op)
        case ops.PX4BridgeEstimates():
            return visitor.visit_px4_bridge_estimates(rule, op)
        case ops.PX4UdralEnergy():
            return visitor.visit_px4_udral_energy(rule, op)
        case ops.ArduPilotTemperature():
            return visitor.visit_ardupilot_temperature(rule, op)
        case ops.ArduPilotCurrent():
            return visitor.visit_ardupilot_current(rule, op)
        case ops.ArduPilotCells():
            return visitor.visit_ardupilot_cells(rule, op)
        case ops.ArduPilotEstimates():
            return visitor.visit_ardupilot_estimates(rule, op)
        case _:
            assert_never(op)
