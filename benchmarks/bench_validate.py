"""``battgen validate`` against what a user would write instead, on uORB battery_status (38 fields, 14 cells).

Three comparisons, each side on the same input kind, the sides taking turns over the rounds, min and
median printed, and the verdicts compared record for record:

* **CLI**: ``battgen validate --message uorb.BatteryStatus FILE.jsonl`` (N records, a fresh process)
  against a script a user writes: ``json`` + fastjsonschema compiled from the schema battgen exports
  (``battgen schema --message uorb.BatteryStatus``), reading the same file line by line in a fresh
  process. Wall and CPU seconds; the records each side finds invalid must be the same lines.
* **API from dicts**: ``BatteryStatus.from_dict(d).validate()`` against the compiled fastjsonschema
  ``check(d)``, over the same parsed dicts (microseconds per record); verdicts compared per record.
* **API on objects**: the generated ``validate()`` against hand-written straight-line checks of the same
  facts on the same instance, and an invalid instance's every violation against jsonschema's
  ``iter_errors`` (which reports fewer: it cannot see the cross-field rule).

fastjsonschema knows drafts 4/6/7, so the export's ``$schema`` is dropped (the keywords used mean the
same there); jsonschema takes the Draft 2020-12 export as it is.

Run: python benchmarks/bench_validate.py [--records N] [--rounds N] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from collections.abc import Callable
from pathlib import Path
from typing import Any

import fastjsonschema
import jsonschema

from codegen.backends.json_schema import message_json_schema
from codegen.frontends.loader import load
from generated.uorb import BatteryStatus

ROOT = Path(__file__).resolve().parent.parent

VALID: dict[str, Any] = {
    "timestamp": 123456789,
    "connected": True,
    "voltage_v": 16.2,
    "current_a": 12.5,
    "current_average_a": 11.8,
    "discharged_mah": 850.0,
    "remaining": 0.63,
    "scale": 1.05,
    "time_remaining_s": 1250.0,
    "temperature": "NaN",
    "cell_count": 4,
    "source": 0,
    "priority": 0,
    "capacity": 5000,
    "cycle_count": 42,
    "average_time_to_empty": 20,
    "manufacture_date": 22000,
    "state_of_health": 97,
    "max_error": 2,
    "id": 1,
    "interface_error": 0,
    "voltage_cell_v": [4.05, 4.06, 4.04, 4.05] + [0.0] * 10,
    "max_cell_voltage_delta": 0.02,
    "is_powering_off": False,
    "is_required": True,
    "warning": 0,
    "faults": 0,
    "full_charge_capacity_wh": 74.0,
    "remaining_capacity_wh": 46.6,
    "over_discharge_count": 0,
    "nominal_voltage": 14.8,
    "internal_resistance_estimate": 0.004,
    "ocv_estimate": 16.4,
    "ocv_estimate_filtered": 16.4,
    "volt_based_soc_estimate": 0.6,
    "voltage_prediction": 16.1,
    "prediction_error": 0.01,
    "estimation_covariance_norm": 0.3,
}
INVALID: dict[str, Any] = {
    **VALID,
    "remaining": 1.5,
    "voltage_v": "NaN",
    "state_of_health": 120,
    "max_error": 0,
    "warning": 5,
    "faults": 1 << 12,
    "voltage_cell_v": [4.05, 4.06, 4.04, 4.05, 5e39] + [0.0] * 9,
}


def hand_written(s: BatteryStatus) -> list[str]:
    """What a careful engineer writes by hand for battery_status: one test per field."""
    out: list[str] = []
    if s.timestamp & -(1 << 64):
        out.append("timestamp")
    if s.connected is not True and s.connected is not False:
        out.append("connected")
    if not -3.4028234663852886e38 <= s.voltage_v <= 3.4028234663852886e38:
        out.append("voltage_v")
    if not -3.4028234663852886e38 <= s.current_a <= 3.4028234663852886e38:
        out.append("current_a")
    if not -3.4028234663852886e38 <= s.current_average_a <= 3.4028234663852886e38:
        out.append("current_average_a")
    if not -3.4028234663852886e38 <= s.discharged_mah <= 3.4028234663852886e38:
        out.append("discharged_mah")
    if not 0.0 <= s.remaining <= 1.0 and s.remaining != -1.0:
        out.append("remaining")
    if not 1.0 <= s.scale <= 3.4028234663852886e38 and s.scale != -1.0:
        out.append("scale")
    v = s.time_remaining_s
    if not -3.4028234663852886e38 <= v <= 3.4028234663852886e38 and v == v:
        out.append("time_remaining_s")
    v = s.temperature
    if not -3.4028234663852886e38 <= v <= 3.4028234663852886e38 and v == v:
        out.append("temperature")
    if s.cell_count & -256:
        out.append("cell_count")
    if s.source not in {0, 1, 2}:
        out.append("source")
    if s.priority & -256:
        out.append("priority")
    if s.capacity & -65536:
        out.append("capacity")
    if s.cycle_count & -65536:
        out.append("cycle_count")
    if s.average_time_to_empty & -65536:
        out.append("average_time_to_empty")
    if s.manufacture_date & -65536:
        out.append("manufacture_date")
    if s.interface_error & -65536:
        out.append("interface_error")
    if s.over_discharge_count & -65536:
        out.append("over_discharge_count")
    if s.state_of_health & -65536 or not 0 <= s.state_of_health <= 100:
        out.append("state_of_health")
    if s.max_error & -65536 or not 1 <= s.max_error <= 100:
        out.append("max_error")
    if s.id & -256:
        out.append("id")
    cells = s.voltage_cell_v
    if len(cells) != 14:
        out.append("voltage_cell_v")
    for c in cells:
        if not -3.4028234663852886e38 <= c <= 3.4028234663852886e38:
            out.append("voltage_cell_v")
            break
    if s.is_powering_off is not True and s.is_powering_off is not False:
        out.append("is_powering_off")
    if s.is_required is not True and s.is_required is not False:
        out.append("is_required")
    if s.warning not in {0, 1, 2, 3, 4, 6, 7}:
        out.append("warning")
    if s.faults & -2048:
        out.append("faults")
    if not -3.4028234663852886e38 <= s.max_cell_voltage_delta <= 3.4028234663852886e38:
        out.append("max_cell_voltage_delta")
    if not -3.4028234663852886e38 <= s.full_charge_capacity_wh <= 3.4028234663852886e38:
        out.append("full_charge_capacity_wh")
    if not -3.4028234663852886e38 <= s.remaining_capacity_wh <= 3.4028234663852886e38:
        out.append("remaining_capacity_wh")
    if not -3.4028234663852886e38 <= s.nominal_voltage <= 3.4028234663852886e38:
        out.append("nominal_voltage")
    if not -3.4028234663852886e38 <= s.internal_resistance_estimate <= 3.4028234663852886e38:
        out.append("internal_resistance_estimate")
    if not -3.4028234663852886e38 <= s.ocv_estimate <= 3.4028234663852886e38:
        out.append("ocv_estimate")
    if not -3.4028234663852886e38 <= s.ocv_estimate_filtered <= 3.4028234663852886e38:
        out.append("ocv_estimate_filtered")
    if not -3.4028234663852886e38 <= s.voltage_prediction <= 3.4028234663852886e38:
        out.append("voltage_prediction")
    if not -3.4028234663852886e38 <= s.prediction_error <= 3.4028234663852886e38:
        out.append("prediction_error")
    if not -3.4028234663852886e38 <= s.estimation_covariance_norm <= 3.4028234663852886e38:
        out.append("estimation_covariance_norm")
    if not 0.0 <= s.volt_based_soc_estimate <= 1.0:
        out.append("volt_based_soc_estimate")
    # the cross-field rules of schemas/rules/uorb-battery-status.yaml
    if s.cell_count > len(cells):
        out.append("cell_count")
    if s.cell_count != 0:
        for i in range(s.cell_count, len(cells)):
            if cells[i] != 0:
                out.append(f"voltage_cell_v[{i}]")
    return out


def best_us(fn: Callable[[], object], number: int, repeat: int) -> float:
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6


def exported_schema() -> dict[str, Any]:
    schema = load([ROOT / "schemas"])
    return message_json_schema(schema, schema.message("uorb.BatteryStatus"))


def measure(number: int = 2000, repeat: int = 5) -> dict[str, float]:
    """Per-call microseconds on one record (best of ``repeat``): the peers and ``from_dict`` +
    ``validate()`` from the same dict; ``validate()`` and the hand-written checks on the same instance."""
    exported = exported_schema()
    validator = jsonschema.Draft202012Validator(exported)
    fast = fastjsonschema.compile({k: v for k, v in exported.items() if k != "$schema"})
    good, bad = BatteryStatus.from_dict(VALID), BatteryStatus.from_dict(INVALID)
    assert good.validate() == [] and validator.is_valid(VALID) and not hand_written(good)
    assert len(bad.validate()) >= 7 and not validator.is_valid(INVALID)
    fast(VALID)

    def fast_invalid() -> None:
        try:
            fast(INVALID)
        except fastjsonschema.JsonSchemaValueException:
            pass

    n_slow = max(number // 20, 10)
    r = {
        "validate": best_us(good.validate, number, repeat),
        "hand_written": best_us(lambda: hand_written(good), number, repeat),
        "from_dict": best_us(lambda: BatteryStatus.from_dict(VALID), number, repeat),
        "from_dict+validate": best_us(lambda: BatteryStatus.from_dict(VALID).validate(), number, repeat),
        "fastjsonschema": best_us(lambda: fast(VALID), number, repeat),
        "jsonschema": best_us(lambda: validator.is_valid(VALID), n_slow, repeat),
        "invalid_from_dict+validate": best_us(lambda: BatteryStatus.from_dict(INVALID).validate(), number, repeat),
        "invalid_jsonschema_iter_errors": best_us(lambda: list(validator.iter_errors(INVALID)), n_slow, repeat),
        "invalid_fastjsonschema_first_error": best_us(fast_invalid, number, repeat),
    }
    r["x_vs_jsonschema"] = r["jsonschema"] / r["from_dict+validate"]
    r["x_vs_fastjsonschema"] = r["fastjsonschema"] / r["from_dict+validate"]
    r["ratio_vs_hand_written"] = r["validate"] / r["hand_written"]
    r["x_invalid_vs_iter_errors"] = r["invalid_jsonschema_iter_errors"] / r["invalid_from_dict+validate"]
    r["violations_reported"] = float(len(bad.validate()))
    r["jsonschema_errors_reported"] = float(len(list(validator.iter_errors(INVALID))))
    return r


def varied_records(n: int, seed: int = 30) -> list[dict[str, Any]]:
    """``n`` battery_status records around VALID, every 97th one out of range (the same fault both sides
    see: a schema range, not a cross-field rule)."""
    rng = random.Random(seed)
    out = []
    for i in range(n):
        cells = [round(rng.uniform(3.4, 4.2), 3) for _ in range(4)] + [0.0] * 10
        record = {
            **VALID,
            "timestamp": 1_000_000 + i * 100_000,
            "voltage_v": round(sum(cells), 3),
            "current_a": round(rng.uniform(0.0, 60.0), 3),
            "remaining": round(rng.uniform(0.0, 1.0), 4),
            "discharged_mah": round(rng.uniform(0.0, 5000.0), 2),
            "temperature": "NaN" if i % 3 else round(rng.uniform(10.0, 60.0), 2),
            "voltage_cell_v": cells,
            "warning": rng.choice((0, 1, 2)),
        }
        if i % 97 == 96:
            record["state_of_health"] = 120
        out.append(record)
    return out


def _summary(times: list[float]) -> str:
    return f"{min(times):9.3f} /{statistics.median(times):9.3f}"


def measure_api(records: list[dict[str, Any]], rounds: int) -> dict[str, float]:
    """from_dict + validate() against fastjsonschema over the same dicts, interleaved rounds;
    seconds per pass over all records."""
    fast = fastjsonschema.compile({k: v for k, v in exported_schema().items() if k != "$schema"})

    def ours() -> list[bool]:
        from_dict = BatteryStatus.from_dict
        return [not from_dict(d).validate() for d in records]

    def peer() -> list[bool]:
        verdicts = []
        for d in records:
            try:
                fast(d)
                verdicts.append(True)
            except fastjsonschema.JsonSchemaValueException:
                verdicts.append(False)
        return verdicts

    if ours() != peer():
        raise RuntimeError("from_dict+validate and fastjsonschema disagree on a record")
    times: dict[str, list[float]] = {"battgen": [], "fastjsonschema": []}
    for _ in range(rounds):
        for name, fn in (("battgen", ours), ("fastjsonschema", peer)):
            started = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - started)
    n = len(records)
    print(f"API from dicts, {n} records, {rounds} interleaved rounds, us/record min / median:")
    for name, t in times.items():
        print(f"  {name:<28} {min(t) / n * 1e6:8.2f} / {statistics.median(t) / n * 1e6:8.2f}")
    ratio = statistics.median(times["fastjsonschema"]) / statistics.median(times["battgen"])
    print(f"  from_dict + validate() is {ratio:.2f}x fastjsonschema (target >= 2x)")
    return {"api battgen_s": statistics.median(times["battgen"]), "api x_vs_fastjsonschema": ratio}


PEER_SCRIPT = """\
import json, sys
import fastjsonschema
with open(sys.argv[1], encoding="utf-8") as f:
    schema = json.load(f)
schema.pop("$schema", None)
check = fastjsonschema.compile(schema)
bad = []
with open(sys.argv[2], encoding="utf-8") as f:
    for n, line in enumerate(f, 1):
        try:
            check(json.loads(line))
        except fastjsonschema.JsonSchemaValueException:
            bad.append(n)
print(json.dumps(bad))
"""


def _run(argv: list[str], env: dict[str, str]) -> tuple[float, float, str]:
    before, start = os.times(), time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    wall, after = time.perf_counter() - start, os.times()
    if done.returncode not in (0, 1):  # 1: an invalid record, still a run
        raise RuntimeError(f"{' '.join(argv)}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, cpu, done.stdout


def measure_cli(records: list[dict[str, Any]], rounds: int) -> dict[str, float]:
    """``battgen validate`` of a JSON Lines file against the json + fastjsonschema script, fresh
    processes, interleaved rounds (a first untimed round writes the bytecode and battgen's IR cache)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    battgen = [sys.executable, "-m", "codegen"]
    with tempfile.TemporaryDirectory() as tmp:
        env["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")
        data = Path(tmp) / "records.jsonl"
        data.write_text("".join(json.dumps(r) + "\n" for r in records), encoding="utf-8")
        schema_file = Path(tmp) / "battery_status.schema.json"
        _, _, text = _run([*battgen, "schema", "--message", "uorb.BatteryStatus"], env)
        schema_file.write_text(text, encoding="utf-8")
        script = Path(tmp) / "peer.py"
        script.write_text(PEER_SCRIPT, encoding="utf-8")
        sides = {
            "battgen validate": [*battgen, "validate", "--message", "uorb.BatteryStatus", str(data)],
            "json + fastjsonschema": [sys.executable, str(script), str(schema_file), str(data)],
        }
        wall: dict[str, list[float]] = {name: [] for name in sides}
        cpu: dict[str, list[float]] = {name: [] for name in sides}
        for round_ in range(rounds + 1):
            for name, argv in sides.items():
                w, c, _ = _run(argv, env)
                if round_:
                    wall[name].append(w)
                    cpu[name].append(c)
        # the same records judged invalid: battgen's JSON report against the script's line numbers
        _, _, report = _run([*sides["battgen validate"], "--format", "json"], env)
        ours = sorted({v["line"] for f in json.loads(report)["files"] for v in f["violations"]})
        _, _, peer = _run(sides["json + fastjsonschema"], env)
        if ours != json.loads(peer):
            raise RuntimeError(f"battgen and fastjsonschema disagree: {ours[:5]} vs {json.loads(peer)[:5]}")
    print(f"CLI, {len(records)} JSON Lines records, fresh processes, {rounds} interleaved rounds (seconds):")
    print(f"  {'':<24} {'wall min / median':>20} {'cpu min / median':>20}")
    for name in sides:
        print(f"  {name:<24} {_summary(wall[name])} {_summary(cpu[name])}")
    ratio = statistics.median(cpu["json + fastjsonschema"]) / statistics.median(cpu["battgen validate"])
    wall_ratio = statistics.median(wall["json + fastjsonschema"]) / statistics.median(wall["battgen validate"])
    print(f"  battgen validate is {ratio:.2f}x the script in CPU, {wall_ratio:.2f}x in wall (target >= 2x)")
    print(f"  invalid records: {len(ours)} on both sides, the same lines")
    return {"cli battgen_s": statistics.median(cpu["battgen validate"]), "cli x_vs_script": ratio}


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=100_000, help="JSON Lines records (CLI and API rows)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=5, help="one-record rows: best of this many")
    parser.add_argument("--number", type=int, default=4000, help="one-record rows: calls per repeat")
    parser.add_argument("--quick", action="store_true", help="10k records, 3 rounds, fewer calls")
    args = parser.parse_args(argv)
    if args.quick:
        args.records, args.rounds, args.repeat, args.number = min(args.records, 10_000), 3, 3, 1000
    records = varied_records(args.records)
    figures = measure_cli(records, args.rounds)
    figures.update(measure_api(records, args.rounds))
    r = measure(args.number, args.repeat)
    print(f"one record ({len(VALID)} fields), microseconds per call, best of {args.repeat}:")
    for key in (
        "from_dict",
        "from_dict+validate",
        "fastjsonschema",
        "jsonschema",
        "validate",
        "hand_written",
        "invalid_from_dict+validate",
        "invalid_fastjsonschema_first_error",
        "invalid_jsonschema_iter_errors",
    ):
        print(f"  {key:<36} {r[key]:10.2f} us")
    print(f"from_dict + validate() is {r['x_vs_jsonschema']:.0f}x faster than jsonschema")
    print(f"from_dict + validate() is {r['x_vs_fastjsonschema']:.1f}x faster than fastjsonschema (target >= 2x)")
    print(f"generated validate() takes {r['ratio_vs_hand_written']:.2f}x the hand-written checks (target <= 1.5x)")
    print(
        f"invalid record: from_dict + validate() reports {r['violations_reported']:.0f} violations "
        f"{r['x_invalid_vs_iter_errors']:.0f}x faster than iter_errors reports "
        f"{r['jsonschema_errors_reported']:.0f} (target >= 1x)"
    )
    assert not math.isnan(r["validate"])
    figures.update({f"one {k}": v for k, v in r.items()})
    return figures


if __name__ == "__main__":
    main()
