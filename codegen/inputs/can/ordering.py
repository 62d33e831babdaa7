"""Whether a battery node sends ``BatteryInfoAux`` before each ``BatteryInfo``.

PX4's DroneCAN battery bridge (``src/drivers/uavcan/sensors/battery.cpp``) keeps the last BatteryInfoAux of a node
and combines it with the node's next BatteryInfo (its ``RawAux`` mode): cell voltages, cycle count and the
remaining-time fields come from the aux message. A node that sends the aux message after its BatteryInfo (or not
in every cycle) gets its battery_status published with the previous cycle's aux values, and its first BatteryInfo
without any; vendors hit this as cells "lagging" one period. This check reports, per node, each BatteryInfo that
is not preceded by a BatteryInfoAux since the node's previous BatteryInfo, once the node is seen sending aux.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ..model import DronecanClass
from .reassembly import Diagnostic, Transfer

BATTERY_INFO = "uavcan.equipment.power.BatteryInfo"
BATTERY_INFO_AUX = "ardupilot.equipment.power.BatteryInfoAux"
_DEFAULT_IDS = {BATTERY_INFO: 1092, BATTERY_INFO_AUX: 20004}  # their default data type ids in the DSDL


def _id_of(known: Mapping[tuple[str, int], DronecanClass], name: str) -> int:
    for (kind, type_id), cls in known.items():
        if kind == "message" and cls.QUALIFIED_NAME.endswith("." + name):
            return type_id
    return _DEFAULT_IDS[name]


@dataclass(slots=True)
class _Node:
    sent_aux: bool = False
    aux_since_info: bool = False
    early_info: Transfer | None = None  # a BatteryInfo seen before the node's first aux message


class AuxOrder:
    """Feed it every transfer; it hands back a ``can-aux-order`` warning for each BatteryInfo out of order."""

    def __init__(self, known: Mapping[tuple[str, int], DronecanClass]) -> None:
        self._info = _id_of(known, BATTERY_INFO)
        self._aux = _id_of(known, BATTERY_INFO_AUX)
        self._nodes: dict[int, _Node] = {}

    def see(self, transfer: Transfer) -> list[Diagnostic]:
        if transfer.id.protocol != "dronecan" or transfer.id.service or transfer.id.anonymous:
            return []
        if transfer.id.data_type_id not in (self._info, self._aux):
            return []
        node = self._nodes.setdefault(transfer.node, _Node())
        if transfer.id.data_type_id == self._aux:
            out = []
            if not node.sent_aux and node.early_info is not None:
                out.append(self._late(node.early_info, "before the node's first BatteryInfoAux"))
            node.sent_aux = node.aux_since_info = True
            node.early_info = None
            return out
        if not node.sent_aux:
            if node.early_info is None:
                node.early_info = transfer
            return []
        late = [] if node.aux_since_info else [self._late(transfer, "without a BatteryInfoAux since the previous one")]
        node.aux_since_info = False
        return late

    def _late(self, info: Transfer, why: str) -> Diagnostic:
        return Diagnostic(
            "can-aux-order",
            f"node {info.node}: BatteryInfo {why}: PX4's bridge pairs it with the previous (or no) BatteryInfoAux",
            info.t,
            info.frame,
            info.node,
            info.id.data_type_id,
            severity="warning",
        )
