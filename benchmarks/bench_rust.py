"""The Rust crate's speed next to the C library and the Python package, in one run: a MAVLink 2 BATTERY_STATUS
frame decode (Rust `decode_frame`, C `battgen_mavlink_BATTERY_STATUS_decode_frame` as bench_c_speed.py builds
it, Python `BatteryStatus.decode_frame`) and one step of the battery failsafe on an armed sample (Rust
`Failsafe::update`, Python `BatteryFailsafe.update`; the C library has no failsafe), and a Cyphal (UDRAL) battery
Status.0.2 decode with 12 cells (Rust, C, the Python package, and pydsdl's own `deserialize`).

Also a converter (DroneCAN BatteryInfo + BatteryInfoAux -> uORB battery_status, strict and px4) in Rust, C and
Python, bench_c_convert.py's record and programs.

Run: python benchmarks/bench_rust.py [--number N]
The Rust side is built with cargo --release --offline into a temp dir; each figure is the best of five runs of N
calls; prints ns per call and the ratios (below 1: Rust is faster).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import timeit
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
CRATE = ROOT / "generated" / "rust"

MAIN = r"""
use battgen::cyphal::reg::udral::service::battery::Status0_2;
use battgen::cyphal_wire::Message as _;
use battgen::convert::{dronecan_to_uorb_px4, dronecan_to_uorb_strict, LossReport};
use battgen::dronecan::ardupilot::equipment::power::BatteryInfoAux;
use battgen::dronecan::uavcan::equipment::power::BatteryInfo;
use battgen::failsafe::{Failsafe, Reading, Sample, Settings, Variants, Vehicle};
use battgen::mavlink::BatteryStatus;
use battgen::mavlink_wire::{decode_frame, encode_frame, Header, MAX_FRAME_LENGTH};
use std::hint::black_box;
use std::time::Instant;

/// ns per call, best of five runs of n calls.
fn best(n: u64, mut f: impl FnMut(u64)) -> f64 {
    let mut best = f64::MAX;
    for _ in 0..5 {
        let t = Instant::now();
        for i in 0..n {
            f(i);
        }
        best = best.min(t.elapsed().as_nanos() as f64 / n as f64);
    }
    best
}

fn main() {
    let n: u64 = std::env::args().nth(1).expect("N").parse().expect("a number");
    let mut msg = BatteryStatus::new();
    for k in 0..4 {
        msg.voltages[k] = 4012 + k as u16;
    }
    msg.current_battery = 1234;
    msg.current_consumed = 1500;
    msg.battery_remaining = 77;
    let mut frame = [0u8; MAX_FRAME_LENGTH];
    let len = encode_frame(&msg, Header { seq: 0, sysid: 1, compid: 1 }, &mut frame);
    let mut sink = 0u64;
    let decode = best(n, |_| {
        let (_, m) = decode_frame::<BatteryStatus>(black_box(&frame[..len])).expect("a frame");
        sink += u64::from(m.voltages[0]);
    });
    let mut settings = Settings::defaults(Vehicle::Rover);
    settings.low_volt = 10.5;
    settings.crt_volt = 10.0;
    settings.low_action = 2;
    settings.volt_source = 1;
    let mut fs = Failsafe::new(Vehicle::Rover, Variants::NONE);
    fs.configure(1, settings).expect("battery 1");
    let mut t: u32 = 0;
    let step = best(n, |i| {
        t += 100;
        let reading = Reading {
            voltage_v: Some(12.0 + (i % 7) as f64 * 0.01),
            current_a: Some(10.0 + (i % 5) as f64),
            consumed_mah: None,
            remaining_mah: None,
        };
        let event = fs.update(t, 1, &black_box(Sample::armed(reading))).expect("a sample");
        sink += u64::from(event.is_some());
    });
    let mut status = Status0_2::new();
    status.cell_voltages_len = 12;
    for (k, v) in status.cell_voltages.iter_mut().take(12).enumerate() {
        *v = 3.7 + 0.01 * k as f32;
    }
    status.temperature_min_max[0].kelvin = 298.15;
    status.available_charge.coulomb = 5000.0;
    let mut cy = [0u8; 600];
    let cn = status.encode(&mut cy, false).expect("an encoding");
    let cyphal = best(n, |_| {
        let m = Status0_2::decode(black_box(&cy[..cn]), false).expect("a status");
        sink += u64::from(m.error.value);
    });
    println!("cyphal_status_decode_rust {cyphal:.2}");
    // a converter: DroneCAN BatteryInfo + BatteryInfoAux -> uORB battery_status, bench_c_convert.py's record
    let mut info = BatteryInfo::new();
    (info.temperature, info.voltage, info.current) = (298.25, 16.796875, -1.5);
    (info.average_power_10sec, info.remaining_capacity_wh, info.full_charge_capacity_wh) = (25.0, 60.0, 80.0);
    (info.hours_to_full_charge, info.status_flags, info.state_of_health_pct) = (0.0, 1, 97);
    (info.state_of_charge_pct, info.model_instance_id) = (75, 7);
    let mut aux = BatteryInfoAux::new();
    aux.voltage_cell_len = 4;
    aux.voltage_cell[..4].copy_from_slice(&[4.199_218_8; 4]);
    (aux.nominal_voltage, aux.cycle_count) = (14.796875, 12);
    let mut rep = LossReport::new();
    for (name, px4) in [("convert_strict_rust", false), ("convert_px4_rust", true)] {
        let ns = best(n, |_| {
            rep.clear();
            let out = if px4 {
                dronecan_to_uorb_px4(black_box(&info), Some(&aux), None, None, &mut rep)
            } else {
                dronecan_to_uorb_strict(black_box(&info), Some(&aux), &mut rep)
            };
            sink += u64::from(out.voltage_v.to_bits() & 1);
        });
        println!("{name} {ns:.2}");
    }
    println!("decode_rust {decode:.2}");
    println!("failsafe_step_rust {step:.2}");
    println!("sink {sink}");
}
"""


def rust(number: int) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        (work / "src").mkdir()
        (work / "Cargo.toml").write_text(
            '[package]\nname = "bench_rust"\nversion = "0.0.0"\nedition = "2021"\n\n'
            f"[dependencies]\nbattgen = {{ path = {str(CRATE)!r} }}\n",
            encoding="utf-8",
        )
        (work / "src" / "main.rs").write_text(MAIN, encoding="utf-8")
        env = {**os.environ, "CARGO_TARGET_DIR": str(work / "target"), "CARGO_NET_OFFLINE": "true"}
        subprocess.run(["cargo", "build", "--release", "--offline", "-q"], cwd=work, env=env, check=True, timeout=600)
        exe = work / "target" / "release" / "bench_rust"
        done = subprocess.run([str(exe), str(number)], capture_output=True, text=True, check=True, timeout=600)
    return {name: float(value) for name, value in (line.split() for line in done.stdout.splitlines())}


def _module(name: str) -> Any:
    """A sibling benchmark (its C program, built the same way)."""
    spec = importlib.util.spec_from_file_location(name, Path(__file__).parent / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def c(number: int) -> dict[str, float]:
    """bench_c_speed.py's figures."""
    result: dict[str, float] = _module("bench_c_speed").run(number)
    return result


def python(number: int) -> dict[str, float]:
    from codegen.apps.failsafe.evaluator import BatteryReading, make_failsafe
    from codegen.apps.failsafe.settings import BatterySettings
    from codegen.apps.failsafe.vehicles import VEHICLES
    from generated.mavlink import BatteryStatus

    msg = BatteryStatus(voltages=[4012, 4013, 4014, 4015] + [65535] * 6, current_battery=1234,
                        current_consumed=1500, battery_remaining=77)  # fmt: skip
    frame = msg.encode_frame()
    decode = min(timeit.repeat(lambda: BatteryStatus.decode_frame(frame), number=number, repeat=5)) / number
    settings = BatterySettings(1, low_volt=10.5, crt_volt=10.0, low_action=2, volt_source=1)
    fs = make_failsafe([settings], VEHICLES["rover"])
    clock = [0.0]
    samples = [BatteryReading(voltage_v=12.0 + (i % 7) * 0.01, current_a=10.0 + (i % 5)) for i in range(35)]

    def step() -> None:
        clock[0] += 0.1
        fs.update(clock[0], samples[int(clock[0] * 10) % 35], armed=True)

    step_s = min(timeit.repeat(step, number=number, repeat=5)) / number
    cyphal_python, cyphal_pydsdl = _cyphal_python(number)
    return {
        "decode_python": decode * 1e9,
        "failsafe_step_python": step_s * 1e9,
        "cyphal_status_decode_python": cyphal_python * 1e9,
        "cyphal_status_decode_pydsdl": cyphal_pydsdl * 1e9,
    }


def _cyphal_python(number: int) -> tuple[float, float]:
    """Seconds per Status.0.2 decode (12 cells): the Python package's, and pydsdl's ``deserialize``."""
    import pydsdl

    from generated.cyphal.reg.udral.service.battery import Status_0_2

    status = Status_0_2.from_dict(
        {
            "heartbeat": {"readiness": {"value": 0}, "health": {"value": 0}},
            "temperature_min_max": [{"kelvin": 298.15}, {"kelvin": 0.0}],
            "available_charge": {"coulomb": 5000.0},
            "error": {"value": 0},
            "cell_voltages": [3.7 + 0.01 * k for k in range(12)],
        }
    )
    data = status.encode()
    root = ROOT / "schemas" / "cyphal"
    spaces = sorted(p for p in root.iterdir() if p.is_dir())
    types = [t for s in spaces for t in pydsdl.read_namespace(s, [o for o in spaces if o != s])]
    t = next(t for t in types if t.full_name == "reg.udral.service.battery.Status" and t.version == (0, 2))
    ours = min(timeit.repeat(lambda: Status_0_2.decode(data), number=number, repeat=5)) / number
    theirs = min(timeit.repeat(lambda: pydsdl.deserialize(t, data), number=number, repeat=5)) / number
    return ours, theirs


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--number", type=int, default=200_000)
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.number = min(args.number, 2000)
    ns = {**rust(args.number), **c(args.number), **python(max(args.number // 20, 1))}
    r, cc, py = ns["decode_rust"], ns["decode_ours"], ns["decode_python"]
    print("BATTERY_STATUS MAVLink 2 frame decode, ns per call:")
    print(f"  Rust {r:8.1f}  C {cc:8.1f}  Python {py:9.1f}   Rust/C {r / cc:5.2f}  Rust/Python {r / py:7.4f}")
    r, py = ns["failsafe_step_rust"], ns["failsafe_step_python"]
    print("battery failsafe, one armed sample, ns per call (the C library has no failsafe):")
    print(f"  Rust {r:8.1f}  Python {py:9.1f}   Rust/Python {r / py:7.4f}")
    r, cc = ns["cyphal_status_decode_rust"], ns["cyphal_status_decode"]
    py, ref = ns["cyphal_status_decode_python"], ns["cyphal_status_decode_pydsdl"]
    print("Cyphal battery Status.0.2 decode (12 cells), ns per call:")
    print(f"  Rust {r:8.1f}  C {cc:8.1f}  Python {py:9.1f}  pydsdl {ref:9.1f}")
    print(f"  Rust/C {r / cc:5.2f}  Python/pydsdl {py / ref:5.2f}")
    convert = _module("bench_c_convert")
    ns |= {f"convert_{k}_c": v for k, v in convert.c_times(args.number).items()}
    ns |= {f"convert_{k}_python": v for k, v in convert.python_times(max(args.number // 100, 1)).items()}
    print("DroneCAN BatteryInfo + BatteryInfoAux -> uORB battery_status, with a loss report, ns per call:")
    for policy in ("strict", "px4"):
        r, cc, py = (ns[f"convert_{policy}_{side}"] for side in ("rust", "c", "python"))
        ratios = f"Rust/C {r / cc:5.2f}  Rust/Python {r / py:7.4f}"
        print(f"  {policy:6} Rust {r:8.1f}  C {cc:8.1f}  Python {py:9.1f}   {ratios}")
    return ns


if __name__ == "__main__":
    if shutil.which("cargo") is None or shutil.which("gcc") is None:
        sys.exit("cargo and gcc are needed")
    main()
