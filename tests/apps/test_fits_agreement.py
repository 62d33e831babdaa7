"""``validate`` and ``convert --policy strict`` agree on every scalar field of uORB BatteryStatus (converted to
MAVLink BATTERY_STATUS) for NaN, +-inf, +-0, the smallest denormal, float32's limits and beyond, and each integer
type's limits +-1: strict refuses a record exactly when validate finds an error in it (issue 32, "strict refuses
what validate refuses").

The cases where they disagree today are listed in DISAGREE and marked as strict expected failures: convert's
strict policy checks only the fields it maps and does not apply the schema's NaN, range, enum and bitmask rules
(codegen/apps/conversion/convert.py). When it does, a listed case passes, the strict xfail fails, and the entry goes.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from codegen.frontends.loader import load
from codegen.ir.fieldtypes import PrimitiveKind, PrimitiveType
from tests.fuzz.targets import run_main

ROOT = Path(__file__).resolve().parents[2]
F32_MAX = 3.4028234663852886e38
BASE = json.loads((ROOT / "tests" / "data" / "instances" / "uorb_valid.json").read_text(encoding="utf-8"))[0]


def _values(ftype: PrimitiveType) -> list[float | int]:
    if ftype.kind is PrimitiveKind.FLOAT:
        return [math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, F32_MAX, -F32_MAX, 3.5e38, -3.5e38]
    if ftype.kind is PrimitiveKind.UINT:
        return [-1, 0, 2**ftype.bits - 1, 2**ftype.bits]
    if ftype.kind is PrimitiveKind.INT:
        low, high = -(2 ** (ftype.bits - 1)), 2 ** (ftype.bits - 1) - 1
        return [low - 1, low, high, high + 1]
    return []


def _cases() -> list[tuple[str, float | int]]:
    (message,) = [m for m in load([ROOT / "schemas"]).messages if m.qualified_name == "uorb.BatteryStatus"]
    return [(f.name, v) for f in message.fields if isinstance(f.type, PrimitiveType) for v in _values(f.type)]


_NAN_NOT_ALLOWED = (
    "voltage_v current_a current_average_a discharged_mah remaining scale max_cell_voltage_delta "
    "full_charge_capacity_wh internal_resistance_estimate ocv_estimate ocv_estimate_filtered "
    "volt_based_soc_estimate voltage_prediction prediction_error estimation_covariance_norm"
).split()
DISAGREE = {
    *((name, "nan") for name in _NAN_NOT_ALLOWED),
    *(("remaining", v) for v in ("3.4028234663852886e+38", "-3.4028234663852886e+38")),
    *(("volt_based_soc_estimate", v) for v in ("3.4028234663852886e+38", "-3.4028234663852886e+38")),
    *(("scale", v) for v in ("0.0", "-0.0", "5e-324", "-3.4028234663852886e+38")),
    ("cell_count", "255"),  # convert exits 1 (cells written as unknown), not 2
    ("source", "255"),
    ("warning", "255"),
    ("state_of_health", "65535"),
    ("max_error", "0"),
    ("max_error", "65535"),
    ("faults", "65535"),
}
CASES = [
    pytest.param(name, value, marks=pytest.mark.xfail(strict=True, reason="strict accepts what validate refuses"))
    if (name, repr(value) if not isinstance(value, float) or not math.isnan(value) else "nan") in DISAGREE
    else pytest.param(name, value)
    for name, value in _cases()
]


@pytest.mark.parametrize(("field", "value"), CASES, ids=[f"{c.values[0]}={c.values[1]!r}" for c in CASES])
def test_strict_conversion_refuses_exactly_what_validate_refuses(tmp_path: Path, field: str, value: float) -> None:
    path = tmp_path / "r.jsonl"
    path.write_text(json.dumps({**BASE, field: value}) + "\n", encoding="utf-8")
    checked, said, _ = run_main(["validate", "--message", "uorb.BatteryStatus", str(path)])
    converted, _, err = run_main(
        ["convert", "--from", "uorb.BatteryStatus", "--to", "mavlink.BATTERY_STATUS", "--policy", "strict", str(path)]
    )
    assert checked in (0, 1) and converted in (0, 1, 2), (checked, converted, err)
    assert (checked == 1) == (converted == 2), f"validate {checked}: {said.strip()[:300]}; convert {converted}: {err}"
