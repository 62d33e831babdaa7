"""One meaning of "fits" in every command (issue 32): ``validate``, ``convert --policy strict`` and the failsafe
agree on every field of the battery messages they share -- uORB BatteryStatus, MAVLink BATTERY_STATUS, DroneCAN
BatteryInfo -- for NaN, +-inf, +-0, the smallest denormal, each type's limits and one beyond, and the field's
"unknown" sentinel, in scalars and in the first element of arrays.

- convert, on every route among the three (uORB, MAVLink and DroneCAN to each other): strict refuses a record
  exactly when validate finds an error in it (both judge by :mod:`codegen.apps.schemas.fits`), whatever the
  target can or cannot hold (what it cannot is written as its unknown and said, never refused);
- the failsafe, on the fields it reads (voltage, current, drawn charge, charge left): a value validate refuses is
  no reading, nor is the field's sentinel as the field stores it (a float32 voltage of 5e-324 is 0.0, uORB's
  unknown); any other value is read as the field stores it.

Where they may differ, and why, is in :data:`EXPLAINED` (empty: none differ today). Not compared here: a binary
log replayed through the battery view (``failsafe`` on a .ulg/.tlog). Its values are as the fields store them
(none beyond its type, so none of the type-bound cases arise), NaN is unknown there as here, but a value within
the type that validate refuses by range (a logged ``remaining`` of 2.0, a tlog ``battery_remaining`` of 101) is
still read by the view's column mappings.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from codegen.apps.conversion.convert import Conversion
from codegen.apps.failsafe.stream import open_reader
from codegen.apps.schemas.package import bundled_schemas, load_schemas
from codegen.errors import BattgenError
from codegen.ir.fields import Field
from codegen.ir.fieldtypes import ArrayType, PrimitiveKind, PrimitiveType
from tests.fuzz.targets import run_main

ROOT = Path(__file__).resolve().parents[2]
UORB = json.loads((ROOT / "tests" / "data" / "instances" / "uorb_valid.json").read_text(encoding="utf-8"))[0]
MAVLINK = {"voltages": [16000] + [65535] * 9, "current_battery": 200, "current_consumed": 100, "temperature": 2500}
MAVLINK |= {"battery_remaining": 50}
DRONECAN = {"voltage": 16.0, "current": 2.0, "state_of_charge_pct": 50, "state_of_health_pct": 100}

# (source message, --to, a record validate accepts whole)
DC = "dronecan.uavcan.equipment.power.BatteryInfo"
SIDES = (
    ("uorb.BatteryStatus", "mavlink.BATTERY_STATUS", UORB),
    ("uorb.BatteryStatus", DC, UORB),
    ("mavlink.BATTERY_STATUS", "uorb.BatteryStatus", MAVLINK),
    ("mavlink.BATTERY_STATUS", DC, MAVLINK),
    (DC, "uorb.BatteryStatus", DRONECAN),
    (DC, "mavlink.BATTERY_STATUS", DRONECAN),
)
# (message, field, value as repr) -> why the commands may differ there; none do today
EXPLAINED: dict[tuple[str, str, str], str] = {}
FLOAT_MAX = {16: 65504.0, 32: 3.4028234663852886e38, 64: 1.7976931348623157e308}
BEYOND = {16: 65520.0, 32: 3.5e38, 64: math.inf}  # the first value the type rounds to infinity


def _values(ftype: PrimitiveType, field: Field) -> list[float | int]:
    if ftype.kind is PrimitiveKind.FLOAT:
        top = FLOAT_MAX[ftype.bits]
        out: list[float | int] = [math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, -5e-324, top, -top]
        out += [BEYOND[ftype.bits], -BEYOND[ftype.bits]]
    elif ftype.kind is PrimitiveKind.UINT:
        out = [-1, 0, 2**ftype.bits - 1, 2**ftype.bits]
    elif ftype.kind is PrimitiveKind.INT:
        low, high = -(2 ** (ftype.bits - 1)), 2 ** (ftype.bits - 1) - 1
        out = [low - 1, low, high, high + 1]
    else:
        return []
    if field.invalid is not None and not any(_same(field.invalid.value, v) for v in out):
        out.append(field.invalid.value)  # the sentinel
    return out


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a) == math.copysign(1, b))


@dataclass(frozen=True)
class Case:
    message: str
    field: str
    value: float | int
    record: dict[str, Any]

    @property
    def key(self) -> tuple[str, str, str]:
        return (
            self.message,
            self.field,
            "nan" if isinstance(self.value, float) and math.isnan(self.value) else repr(self.value),
        )


def _cases(message: str, base: dict[str, Any]) -> list[Case]:
    schema = load_schemas(bundled_schemas())
    out = []
    for f in schema.message(message).fields:
        ftype = f.type.element if isinstance(f.type, ArrayType) else f.type
        if not isinstance(ftype, PrimitiveType) or f.is_padding:
            continue
        for v in _values(ftype, f):
            if isinstance(f.type, ArrayType):
                length = f.type.capacity if not f.type.dynamic else 1
                rest = list(base.get(f.name, [0] * length))[1:length]
                value: Any = [v, *rest]
            else:
                value = v
            out.append(Case(message, f.name, v, {**base, f.name: value}))
    return out


def _validate_errors(tmp_path: Path, message: str, cases: list[Case]) -> set[int]:
    """The cases (by index) in which ``battgen validate`` finds an error, in one run over all of them."""
    path = tmp_path / f"{message}.jsonl"
    path.write_text("".join(json.dumps(c.record) + "\n" for c in cases), encoding="utf-8")
    code, out, err = run_main(["validate", "--message", message, "--format", "json", str(path)])
    assert code in (0, 1), err
    (report,) = json.loads(out)["files"]
    assert report["records"] == len(cases) and not report["unreadable"]
    return {v["record"] for v in report["violations"] if v["severity"] == "error" and not v["waived"]}


def _strict_refuses(conversion: Conversion, case: Case) -> bool:
    line = (json.dumps(case.record) + "\n").encode()
    try:
        list(conversion.run(io.BytesIO(line), "case.jsonl", "jsonl"))
    except BattgenError:
        return True
    return False


@pytest.mark.parametrize(("message", "target", "base"), SIDES, ids=[f"{s[0]}->{s[1]}" for s in SIDES])
def test_strict_conversion_refuses_exactly_what_validate_refuses(
    tmp_path: Path, message: str, target: str, base: dict[str, Any]
) -> None:
    cases = _cases(message, base)
    refused_by_validate = _validate_errors(tmp_path, message, cases)
    assert 0 not in refused_by_validate or cases[0].record != base  # the base record itself is valid
    conversion = Conversion(None, message, target, "strict")
    differ = [
        f"{c.field}={c.value!r}: validate {'refuses' if i in refused_by_validate else 'accepts'}, strict "
        f"{'refuses' if refused else 'converts'}"
        for i, c in enumerate(cases)
        if (refused := _strict_refuses(conversion, c)) != (i in refused_by_validate) and c.key not in EXPLAINED
    ]
    assert not differ, "\n".join(differ)
    assert refused_by_validate  # not vacuous: the limits +-1 are refused, whatever else is


# what the failsafe reads of each message: field -> the reading's quantity (and the factor to it)
READS: dict[str, dict[str, tuple[str, float]]] = {
    "uorb.BatteryStatus": {"voltage_v": ("voltage_v", 1.0), "current_a": ("current_a", 1.0)}
    | {"discharged_mah": ("consumed_mah", 1.0)},
    "mavlink.BATTERY_STATUS": {"current_battery": ("current_a", 0.01), "current_consumed": ("consumed_mah", 1.0)},
    "dronecan.uavcan.equipment.power.BatteryInfo": {"voltage": ("voltage_v", 1.0), "current": ("current_a", 1.0)},
}
STORED = {16: np.float16, 32: np.float32}


def _stored(case: Case, bits: int | None) -> float:
    """The value as its field stores it (a float32 of 5e-324 is 0.0)."""
    if bits in STORED and isinstance(case.value, float):
        with np.errstate(over="ignore"):
            return float(STORED[bits](case.value))
    return float(case.value)


def _failsafe_cases() -> Iterator[tuple[Case, int | None, float | None]]:
    schema = load_schemas(bundled_schemas())
    for message, base in {m: b for m, _, b in SIDES}.items():
        for case in _cases(message, base):
            if case.field in READS[message]:
                f = schema.message(message).field(case.field)
                ftype = f.type if isinstance(f.type, PrimitiveType) else None
                sentinel = f.invalid.value if f.invalid is not None else None
                yield case, (ftype.bits if ftype is not None and ftype.kind is PrimitiveKind.FLOAT else None), sentinel


def test_the_failsafe_reads_no_value_validate_refuses_and_every_other_as_stored(tmp_path: Path) -> None:
    reader = open_reader(None)
    by_message: dict[str, list[tuple[Case, int | None, float | None]]] = {}
    for item in _failsafe_cases():
        by_message.setdefault(item[0].message, []).append(item)
    differ = []
    for message, items in by_message.items():
        refused = _validate_errors(tmp_path, message, [c for c, _, _ in items])
        for i, (case, bits, sentinel) in enumerate(items):
            reading = reader.sample({"t": 1, "armed": True, "message": message, "data": case.record}, "s.jsonl", 1)
            quantity, factor = READS[message][case.field]
            got = getattr(reading.battery, quantity)
            stored = _stored(case, bits)
            unknown = i in refused or (sentinel is not None and _same_or_equal(stored, sentinel))
            expected = None if unknown else stored * factor
            if case.key not in EXPLAINED and not _agrees(got, expected):
                differ.append(f"{message} {case.field}={case.value!r}: failsafe reads {got!r}, expected {expected!r}")
    assert not differ, "\n".join(differ)


def _same_or_equal(stored: float, sentinel: float) -> bool:
    """The sentinel as the firmware compares it: -0.0 is uORB's unknown voltage 0 too."""
    return (math.isnan(stored) and math.isnan(sentinel)) or stored == sentinel


def _agrees(got: float | None, expected: float | None) -> bool:
    if got is None or expected is None:
        return got is expected
    return got == pytest.approx(expected, rel=1e-9, abs=0.0)


@pytest.mark.parametrize("name", ["sample_log_small.ulg", "sample_px4_events.ulg"])
def test_strict_converts_real_px4_logs_as_validate_passes_them(name: str, tmp_path: Path) -> None:
    """PX4 writes max_error = 0 (its battery library never sets it): validate waives that by the log's firmware
    (profiles/px4.yaml), and strict judges the log the same way; without the profile validate refuses it."""
    log = ROOT.parent / "shared" / "data" / "ulog" / name
    if not log.is_file():
        pytest.skip(f"{log} not present")
    checked, _, _ = run_main(["validate", str(log)])
    unprofiled, said, _ = run_main(["validate", "--profile", "", str(log)])
    out = tmp_path / "out.jsonl"
    converted, _, err = run_main(["convert", "--from", "uorb", "--to", "mavlink", str(log), "-o", str(out)])
    assert checked == 0 and unprofiled == 1 and "max_error = 0" in said
    assert converted in (0, 1), err  # 1: values MAVLink cannot hold, written as its unknown
    assert "--policy strict" not in err and out.read_text(encoding="utf-8").count("\n") > 0


def test_strict_leaves_out_what_a_log_lacks_as_validate_does(tmp_path: Path) -> None:
    """An older PX4 log without ``max_error`` (its field keeps the default 0, which the range refuses): neither
    command judges a value the log does not hold, with or without the firmware's profile."""
    log = ROOT.parent / "shared" / "corpus" / "realworld3" / "ulog" / "px4tools_19_56_46.ulg"
    if not log.is_file():
        pytest.skip(f"{log} not present")
    checked, _, notes = run_main(["validate", "--profile", "", str(log)])
    out = tmp_path / "out.jsonl"
    converted, _, err = run_main(["convert", "--from", "uorb", "--to", "mavlink", str(log), "-o", str(out)])
    assert checked == 0 and "max_error" in notes  # named among the fields not checked
    assert converted in (0, 1) and "--policy strict" not in err, err
    assert out.read_text(encoding="utf-8").count("\n") == 13


@pytest.mark.parametrize(("consumed", "fires"), [(2**31 - 1, True), (2**31, False), (950, True)])
def test_the_failsafe_acts_on_no_charge_validate_refuses(tmp_path: Path, consumed: int, fires: bool) -> None:
    """A MAVLink current_consumed of 2^31 does not fit its int32 (validate's error): no drawn charge, no LOW; the
    int32 limit itself is a value the field holds and acts as any other."""
    params = tmp_path / "m.param"
    params.write_text("BATT_MONITOR 4\nBATT_CAPACITY 1000\nBATT_LOW_MAH 100\nBATT_FS_LOW_ACT 2\n", encoding="utf-8")
    data = {"voltages": [16000] + [65535] * 9, "current_battery": 200}
    samples = [
        {"t": t, "armed": True, "message": "mavlink.BATTERY_STATUS", "data": {**data, "current_consumed": c}}
        for t, c in [(1, 100), (2, 100), *((t, consumed) for t in range(3, 10))]
    ]
    stream = tmp_path / "s.jsonl"
    stream.write_text("".join(json.dumps(s) + "\n" for s in samples), encoding="utf-8")
    code, out, err = run_main(["failsafe", "--vehicle", "copter", "--params", str(params), str(stream)])
    assert code == 0, err
    assert ("LOW" in out) is fires, out
