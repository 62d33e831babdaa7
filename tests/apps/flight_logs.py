"""Synthetic PX4 flights for the report tests and benchmark: battery_status of several packs at a fixed rate.

A 6S pack discharges through a hover-and-climb profile (load steps every 30 s), its voltage the open-circuit
voltage of its charge less I·R, each cell the pack's sixth with a fixed offset (pack 2 drifting apart), so that
the report has sag, load steps, imbalance and a voltage that ends below typical LOW/CRITICAL thresholds. Written
with the generated ULog writer as a real ``.ulg``.
"""

from __future__ import annotations

import math
from pathlib import Path

from generated import _ulog_writer
from generated.uorb import BatteryStatus

CELLS = 6
CAPACITY_MAH = 10000
RESISTANCE = (0.030, 0.045)  # ohm, per pack
OFFSETS = ((0.0, 0.004, -0.003, 0.002, -0.002, 0.001), (0.0, 0.010, -0.012, 0.006, -0.020, 0.003))


def _ocv_per_cell(soc: float) -> float:
    """A LiPo-like open-circuit voltage per cell for a state of charge in [0, 1]."""
    return 3.3 + 0.9 * soc - 0.25 * math.exp(-12 * soc) + 0.05 * math.sin(3 * soc)


def write_flight(path: Path, seconds: float = 600.0, hz: float = 10.0, packs: int = 2) -> Path:
    """A flight of ``seconds`` at ``hz`` battery_status records per pack (multi_id 0, 1, ...)."""
    records = []
    n = int(seconds * hz)
    drawn = [0.0] * packs
    for k in range(n):
        t = k / hz
        step = int(t // 30) % 3
        current_base = (18.0, 42.0, 25.0)[step]  # hover, climb, cruise
        for p in range(packs):
            current = current_base * (1.0 + 0.1 * p)
            drawn[p] += current / hz / 3.6  # mAh
            soc = max(0.0, 1.0 - 0.97 * k / max(1, n - 1))  # the whole flight uses 97 % of the pack
            cell = _ocv_per_cell(soc) - current * RESISTANCE[p] / CELLS
            cells = [cell + OFFSETS[p][c] * (1 + 2 * (1 - soc)) for c in range(CELLS)]
            records.append(
                (
                    BatteryStatus(
                        timestamp=int(t * 1e6) + 1_000_000,
                        connected=True,
                        voltage_v=sum(cells),
                        current_a=current,
                        current_average_a=current,
                        discharged_mah=drawn[p],
                        remaining=soc,
                        temperature=25.0 + 10.0 * (1 - soc),
                        cell_count=CELLS,
                        capacity=CAPACITY_MAH,
                        id=p + 1,
                        max_error=1,
                        voltage_cell_v=cells + [0.0] * (14 - CELLS),
                    ),
                    p,
                )
            )
    _ulog_writer.write(path, records)
    return path


def write_capture_flight(
    path: Path,
    *,
    seconds: float = 60.0,
    hz: float = 5.0,
    node: int = 20,
    serial: int = 777,
    health: int = 95,
    cycles: int = 10,
    resistance: float = 0.03,
) -> Path:
    """A candump capture of one DroneCAN battery node: BatteryInfo at ``hz`` through a load profile, its pack
    identified by ``model_instance_id`` (the serial the report follows across flights)."""
    import can  # python-can writes the capture as candump does

    from codegen.inputs.can import wire
    from generated.dronecan.uavcan.equipment.power import BatteryInfo

    writer = can.Logger(str(path))
    try:
        n = int(seconds * hz)
        for k in range(n):
            t = k / hz
            current = (15.0, 35.0)[int(t // 10) % 2]
            soc = 1.0 - 0.8 * k / max(1, n - 1)
            volts = CELLS * _ocv_per_cell(soc) - current * resistance
            info = BatteryInfo(
                voltage=volts,
                current=current,
                temperature=300.0,
                state_of_charge_pct=int(soc * 100),
                state_of_health_pct=health,
                battery_id=0,
                model_instance_id=serial,
                model_name=b"6S pack",
                remaining_capacity_wh=soc * 200,
                full_charge_capacity_wh=200,
            )
            payload = info.encode()
            signature = BatteryInfo.DATA_TYPE_SIGNATURE
            for data in wire.split_transfer(payload, signature, k % 32):
                writer.on_message_received(
                    can.Message(
                        timestamp=1_700_000_000 + t,
                        arbitration_id=wire.message_id(1092, node),
                        is_extended_id=True,
                        data=data,
                    )
                )
    finally:
        writer.stop()
    return path
