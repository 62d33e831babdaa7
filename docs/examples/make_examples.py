"""Writes the binary example files the documentation uses, from the project's own synthetic flights.

    .venv/bin/python docs/examples/make_examples.py [FOLDER]     # default: this folder

- ``flight.ulg``: a PX4 log of a two-pack 6S copter, 120 s at 2 Hz per pack, armed from 5 s (the pack
  voltages end below ``copter.param``'s LOW and CRITICAL thresholds);
- ``bench.log``: a candump capture of one DroneCAN battery node (BatteryInfo at 2 Hz for 30 s);
- ``cyphal-bench.txt``: candump's screen output (``candump -ta``) of one UDRAL battery node on Cyphal/CAN
  (node 12: energy_source on subject 4097 at 5 Hz, status on 4096 at 1 Hz, for 10 s);
- ``flight.bin``: an ArduPilot DataFlash log with its own PARM, ARM and BAT records.

The text examples beside them (``telemetry.jsonl``, ``smart-battery.jsonl``, ``status.json``, ``board.dts``,
``copter.param``) are written by hand. ``tests/test_docs_examples.py`` regenerates these four files and
checks they are the ones shipped, then runs every command of the README and the docs on this folder.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path[:0] = [str(ROOT / "tests" / "apps"), str(ROOT / "tests" / "inputs")]  # the project's flight writers

from dataflash_writer import battery_log  # noqa: E402
from flight_logs import write_capture_flight, write_cyphal_capture, write_flight  # noqa: E402


def make(folder: Path) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    ulg = write_flight(folder / "flight.ulg", seconds=120.0, hz=2.0, packs=2, armed=(5.0, 110.0))
    capture = write_capture_flight(folder / "bench.log", seconds=30.0, hz=2.0)
    cyphal = write_cyphal_capture(folder / "cyphal-bench.txt")
    rows = [(t / 2, 0, 16.6 - 0.02 * t, 12.0 + 6.0 * (t // 20 % 2), 3.3 * t) for t in range(240)]
    params = {"BATT_MONITOR": 4, "BATT_CAPACITY": 2200, "BATT_LOW_VOLT": 14.4, "BATT_CRT_VOLT": 13.6,
              "BATT_FS_LOW_ACT": 2, "BATT_FS_CRT_ACT": 1, "RTL_ALT": 1500}  # fmt: skip
    dataflash = battery_log(folder / "flight.bin", params, rows, [(2.0, True), (118.0, False)])
    return [ulg, capture, cyphal, dataflash]


if __name__ == "__main__":
    for path in make(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE):
        print(f"wrote {path}")
