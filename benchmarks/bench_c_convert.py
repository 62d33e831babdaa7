"""The generated C converters against the Python package's on the same record: DroneCAN BatteryInfo
(+ BatteryInfoAux) -> uORB battery_status under the strict policy (through the concepts) and the
px4 policy (PX4's uavcan bridge), with a loss report.

Run: python benchmarks/bench_c_convert.py [--number N]
The C is built with gcc -O2 into a temp dir and timed in one process (best of five runs of N calls);
the Python converter is timed with timeit (best of five). Prints ns per record and the ratio.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"
sys.path.insert(0, str(ROOT))

PROGRAM = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <time.h>
#include "battgen.h"

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static volatile float sink;

#define BEST(label, call)                                                       \
  do {                                                                          \
    double best = 1e300;                                                        \
    int r;                                                                      \
    for (r = 0; r < 5; r++) {                                                   \
      double t0 = now(), t;                                                     \
      long i;                                                                   \
      for (i = 0; i < N; i++) { battgen_loss_clear(&rep); call; sink = out.voltage_v; } \
      t = (now() - t0) / (double)N;                                             \
      if (t < best) { best = t; }                                               \
    }                                                                           \
    printf("%s %.1f\n", label, best);                                           \
  } while (0)

int main(void) {
  const long N = NUMBER;
  static battgen_loss_report rep;
  battgen_dronecan_uavcan_equipment_power_BatteryInfo info = {0};
  battgen_dronecan_ardupilot_equipment_power_BatteryInfoAux aux = {0};
  battgen_uorb_BatteryStatus out;
  info.temperature = 298.25f; info.voltage = 16.796875f; info.current = -1.5f;
  info.average_power_10sec = 25.0f; info.remaining_capacity_wh = 60.0f; info.full_charge_capacity_wh = 80.0f;
  info.hours_to_full_charge = 0.0f; info.status_flags = 1; info.state_of_health_pct = 97;
  info.state_of_charge_pct = 75; info.model_instance_id = 7;
  aux.voltage_cell_len = 4; aux.voltage_cell[0] = 4.19921875f; aux.voltage_cell[1] = 4.19921875f;
  aux.voltage_cell[2] = 4.19921875f; aux.voltage_cell[3] = 4.19921875f; aux.nominal_voltage = 14.796875f;
  aux.cycle_count = 12;
  BEST("strict", battgen_convert_dronecan_to_uorb_strict(&info, &aux, &out, &rep));
  BEST("px4", battgen_convert_dronecan_to_uorb_px4(&info, &aux, NULL, NULL, &out, &rep));
  return 0;
}
"""


def c_times(number: int) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "bench.c"
        src.write_text(PROGRAM.replace("NUMBER", str(number)), encoding="utf-8")
        exe = Path(tmp) / "bench"
        files = [str(src), str(GENERATED / "convert.c")]
        subprocess.run(["gcc", "-O2", "-std=c99", "-I", str(GENERATED), *files, "-o", str(exe)], check=True)
        out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    return {k: float(v) for k, v in (line.split() for line in out.splitlines())}


def python_times(number: int) -> dict[str, float]:
    import generated.convert as converters
    from generated.dronecan.ardupilot.equipment.power import BatteryInfoAux
    from generated.dronecan.uavcan.equipment.power import BatteryInfo

    info = BatteryInfo.from_dict(
        {
            "temperature": 298.25,
            "voltage": 16.796875,
            "current": -1.5,
            "average_power_10sec": 25.0,
            "remaining_capacity_wh": 60.0,
            "full_charge_capacity_wh": 80.0,
            "hours_to_full_charge": 0.0,
            "status_flags": 1,
            "state_of_health_pct": 97,
            "state_of_charge_pct": 75,
            "model_instance_id": 7,
        }
    )
    aux = BatteryInfoAux.from_dict({"voltage_cell": [4.19921875] * 4, "nominal_voltage": 14.796875, "cycle_count": 12})
    convert = converters.converter("dronecan", "uorb")
    out = {}
    for policy in ("strict", "px4"):

        def once(policy: str = policy) -> None:
            convert(info, aux, policy=policy, report=converters.LossReport())

        out[policy] = min(timeit.repeat(once, number=number, repeat=5)) / number * 1e9
    return out


def main(argv: list[str] | None = None) -> dict[str, float]:
    """Times both policies; returns ns per record by ``<side>_<policy>`` (``c_strict``, ``python_px4``, ...)."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--number", type=int, default=20000)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.number = min(args.number, 50)
    if shutil.which("gcc") is None:
        print("gcc not installed", file=sys.stderr)
        return {}
    c = c_times(args.number * 50)
    py = python_times(args.number)
    for policy in ("strict", "px4"):
        ratio = py[policy] / c[policy]
        print(f"dronecan->uorb {policy}: C {c[policy]:.1f} ns/record, Python {py[policy]:.0f} ns/record, x{ratio:.0f}")
    return {**{f"c_{k}": v for k, v in c.items()}, **{f"python_{k}": v for k, v in py.items()}}


if __name__ == "__main__":
    main()
