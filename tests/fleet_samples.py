"""Small inputs for the fleet export tests: a tlog, a JSON Lines file, the shared real logs."""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path

import pytest
from shared_data import real_logs

from generated.mavlink import BatteryStatus as MavBattery

LOGS = real_logs()
# outside CI a test of the real logs skips without them; under CI it fails (shared_data.missing)
needs_logs = pytest.mark.skipif(not LOGS and not os.environ.get("CI"), reason="shared sample logs not present")
DOCUMENTED = {
    "log", "source", "vehicle", "battery", "t", "time", "armed", "message", "pack_voltage", "current",
    "state_of_charge", "temperature", "cell_voltages", "discharged", "remaining_energy",
}  # fmt: skip


def tlog(path: Path) -> Path:
    out = bytearray()
    for i in range(6):
        msg = MavBattery(
            id=1,
            current_battery=1500 if i < 3 else 3500,  # cA
            voltages=[4100 - i * 10, 4090 - i * 10, 4080, 65535, 65535, 65535, 65535, 65535, 65535, 65535],
            battery_remaining=-1 if i == 0 else 90 - i,
            temperature=32767 if i == 0 else 2500,
        )
        out += struct.pack(">Q", 1_700_000_000_000_000 + i * 500_000) + msg.encode_frame(seq=i, sysid=7, compid=1)
    path.write_bytes(bytes(out))
    return path


def jsonl(path: Path) -> Path:
    lines = [
        {"timestamp": 1_000_000 * (i + 1), "voltage_v": 12.0 - i * 0.1, "current_a": 5.0, "remaining": -1 if i else 0.8}
        for i in range(4)
    ]
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path
