"""The generated C library's speed against mavgen's C (pymavlink's generator, run here on the same XML):
BATTERY_STATUS frame encode and decode, and DroneCAN BatteryInfo decode and Cyphal (UDRAL) battery Status.0.2
encode and decode against a memcpy of their payloads.

Run: python benchmarks/bench_c_speed.py [--number N]
Both sides are built with gcc -O2 into a temp dir and timed in one process, best of five runs of N calls;
prints ns per call and the ratios (below 1: ours is faster).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"

PROGRAM = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "battery/mavlink.h"
#include "battgen.h"

typedef battgen_mavlink_BATTERY_STATUS ours_t;
typedef battgen_dronecan_uavcan_equipment_power_BatteryInfo info_t;
typedef battgen_cyphal_reg_udral_service_battery_Status_0_2 udral_t;
static volatile unsigned sink;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

#define BEST(label, body)                                                       \
  do {                                                                          \
    double best = 1e300;                                                        \
    int r;                                                                      \
    for (r = 0; r < 5; r++) {                                                   \
      double t0 = now();                                                        \
      long i;                                                                   \
      for (i = 0; i < N; i++) { body; }                                         \
      if ((now() - t0) / (double)N < best) { best = (now() - t0) / (double)N; } \
    }                                                                           \
    printf("%s %.2f\n", label, best);                                           \
  } while (0)

int main(void) {
  const long N = NUMBER;
  ours_t ours;
  mavlink_battery_status_t theirs;
  mavlink_message_t msg;
  mavlink_status_t status;
  battgen_mavlink_header h = {0, 1, 1};
  uint8_t frame[MAVLINK_MAX_PACKET_LEN];
  uint8_t frame2[MAVLINK_MAX_PACKET_LEN];
  size_t n, n2, k;
  info_t info;
  uint8_t payload[BATTGEN_DRONECAN_UAVCAN_EQUIPMENT_POWER_BATTERYINFO_MAX_BYTES], copy[64];
  size_t pn = 0;
  udral_t udral;
  uint8_t cy[BATTGEN_CYPHAL_REG_UDRAL_SERVICE_BATTERY_STATUS_0_2_BUFFER_BYTES], cycopy[600];
  size_t cn = 0;
  memset(&udral, 0, sizeof udral);
  udral.cell_voltages_len = 12;
  for (k = 0; k < 12; k++) { udral.cell_voltages[k] = 3.7f + 0.01f * (float)k; }
  udral.temperature_min_max[0].kelvin = 298.15f;
  udral.available_charge.coulomb = 5000.0f;
  memset(&ours, 0, sizeof ours);
  memset(&theirs, 0, sizeof theirs);
  memset(&info, 0, sizeof info);
  for (k = 0; k < 10; k++) { ours.voltages[k] = theirs.voltages[k] = (uint16_t)(3700 + k); }
  ours.current_consumed = theirs.current_consumed = 1234;
  ours.battery_remaining = theirs.battery_remaining = 55;
  ours.temperature = theirs.temperature = 2500;
  info.voltage = 16.8f;
  info.current = 2.5f;
  info.model_name_len = 8;
  battgen_dronecan_uavcan_equipment_power_BatteryInfo_encode(&info, true, payload, &pn);

  BEST("encode_ours", n = battgen_mavlink_BATTERY_STATUS_encode_frame(&ours, h, frame); sink += frame[n - 1]);
  BEST("encode_mavgen", mavlink_msg_battery_status_encode(1, 1, &msg, &theirs);
       n2 = mavlink_msg_to_send_buffer(frame2, &msg); sink += frame2[n2 - 1]);
  if (n != n2 || memcmp(frame + 10, frame2 + 10, n - 12) != 0) { printf("frames differ\n"); return 1; }
  BEST("decode_ours", battgen_mavlink_BATTERY_STATUS_decode_frame(frame, n, &h, &ours); sink += ours.voltages[0]);
  BEST("decode_mavgen", for (k = 0; k < n2; k++) { mavlink_parse_char(MAVLINK_COMM_1, frame2[k], &msg, &status); }
       mavlink_msg_battery_status_decode(&msg, &theirs); sink += theirs.voltages[0]);
  BEST("dronecan_info_decode", battgen_dronecan_uavcan_equipment_power_BatteryInfo_decode(payload, pn, true, &info);
       sink += info.state_of_charge_pct);
  BEST("dronecan_info_memcpy", memcpy(copy, payload, pn); sink += copy[pn - 1]; payload[0] ^= (uint8_t)sink);
  BEST("cyphal_status_encode", battgen_cyphal_reg_udral_service_battery_Status_0_2_encode(&udral, false, cy, &cn);
       sink += cy[cn - 1]; udral.error.value = (uint8_t)sink);
  BEST("cyphal_status_decode", battgen_cyphal_reg_udral_service_battery_Status_0_2_decode(cy, cn, false, &udral);
       sink += udral.error.value);
  BEST("cyphal_status_memcpy", memcpy(cycopy, cy, cn); sink += cycopy[cn - 1]; cy[0] ^= (uint8_t)sink);
  return 0;
}
"""


def run(number: int) -> dict[str, float]:
    """ns per call of each timed operation."""
    from pymavlink.generator import mavgen

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        opts = mavgen.Opts(str(out / "mavgen"), wire_protocol="2.0", language="C", validate=False)
        if not mavgen.mavgen(opts, [str(ROOT / "schemas" / "mavlink" / "battery.xml")]):
            raise RuntimeError("mavgen failed")
        (out / "bench.c").write_text(PROGRAM.replace("NUMBER", str(number)), encoding="utf-8")
        sources = [str(GENERATED / "mavlink.c"), str(GENERATED / "dronecan.c"), str(GENERATED / "cyphal.c")]
        cc = ["gcc", "-O2", "-std=c99", "-w", "-I", str(out / "mavgen"), "-I", str(GENERATED)]
        subprocess.run([*cc, str(out / "bench.c"), *sources, "-o", str(out / "bench")], check=True, timeout=300)
        done = subprocess.run([str(out / "bench")], capture_output=True, text=True, check=True, timeout=600)
    return {name: float(value) for name, value in (line.split() for line in done.stdout.splitlines())}


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--number", type=int, default=200_000)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.number = min(args.number, 2000)
    ns = run(args.number)
    print("BATTERY_STATUS (MAVLink 2 frame), ns per call:")
    for what in ("encode", "decode"):
        ours, theirs = ns[f"{what}_ours"], ns[f"{what}_mavgen"]
        print(f"  {what}: battgen {ours:8.1f}  mavgen {theirs:8.1f}  ratio {ours / theirs:5.2f}")
    decode, floor = ns["dronecan_info_decode"], ns["dronecan_info_memcpy"]
    print(
        f"DroneCAN BatteryInfo decode: {decode:.1f} ns, {decode / floor:.1f}x a memcpy of the payload ({floor:.1f} ns)"
    )
    floor = ns["cyphal_status_memcpy"]
    for what in ("encode", "decode"):
        took = ns[f"cyphal_status_{what}"]
        print(f"Cyphal Status.0.2 (12 cells) {what}: {took:.1f} ns, {took / floor:.1f}x a memcpy ({floor:.1f} ns)")
    return ns


if __name__ == "__main__":
    if shutil.which("gcc") is None:
        sys.exit("gcc not installed")
    main()
