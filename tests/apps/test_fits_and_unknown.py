"""One meaning of "fits" and "unknown" in every command: a value beyond what the target allows is clamped to the
nearest value it allows (never onto its unknown marker, never outside its range, +-inf like any finite excess)
and said so; strict conversion refuses what validate refuses; the failsafe and the export read a float field as
the field stores it."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.view import read_view
from codegen.cli.main import main


def _convert(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, source: str, target: str, record: dict[str, Any]
) -> tuple[int, list[dict[str, Any]], str]:
    path = tmp_path / "in.jsonl"
    path.write_text(json.dumps(record) + "\n", encoding="utf-8")
    code = main(["convert", "--from", source, "--to", target, "--report", str(path)])
    out, err = capsys.readouterr()
    return code, [json.loads(line) for line in out.splitlines()], err


def _clamped(result: dict[str, Any]) -> dict[str, str]:
    return {e["field"].rsplit(".", 1)[-1]: e.get("detail", "") for e in result["loss"] if e["kind"] == "clamped"}


# a uORB record validate accepts (max_error: PX4's range is 1..100, its default 0 is refused)
VALID_UORB = {"timestamp": 1, "voltage_v": 12.0, "max_error": 1}


@pytest.mark.parametrize(
    ("value", "field", "expected"),
    [
        ({"temperature": 400.0}, "temperature", 32766),  # INT16_MAX is MAVLink's unknown temperature
        ({"current_a": 3e36}, "current_battery", 32767),  # a float32 current no int16 holds
        ({"current_a": -3e36}, "current_battery", -32768),
    ],
)
def test_uorb_to_mavlink_clamps_into_what_the_target_allows(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, value: dict[str, float], field: str, expected: int
) -> None:
    record = {**VALID_UORB, **value}
    code, (result,), _ = _convert(capsys, tmp_path, "uorb.BatteryStatus", "mavlink.BATTERY_STATUS", record)
    assert code == 0
    assert result["record"][field] == expected
    assert field in _clamped(result)


@pytest.mark.parametrize(
    ("target", "field"),
    [
        ("mavlink.BATTERY_STATUS", "battery_remaining"),
        ("dronecan.uavcan.equipment.power.BatteryInfo", "state_of_charge_pct"),
    ],
)
@pytest.mark.parametrize(("charge", "expected"), [(2.0, 100), (-0.05, 0)])
def test_a_charge_beyond_full_or_empty_clamps_into_range_not_onto_the_unknown(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, target: str, field: str, charge: float, expected: int
) -> None:
    """From the shared state (a uORB ``remaining`` of 2.0 is validate's error, so strict refuses it): MAVLink's
    unknown is -1 and DroneCAN's 127, the ranges 0..100."""
    record = {"pack_voltage": 12.0, "state_of_charge": charge}
    code, (result,), _ = _convert(capsys, tmp_path, "concepts", target, record)
    assert code == 0
    held = result["record"].get("info", result["record"])
    assert held[field] == expected
    assert field in _clamped(result)


def test_a_charge_above_full_is_100_percent_in_dronecan_not_its_unknown(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    record = {"pack_voltage": 12.0, "state_of_charge": 2.0}
    code, (result,), _ = _convert(capsys, tmp_path, "concepts", "dronecan.uavcan.equipment.power.BatteryInfo", record)
    assert code == 0
    assert result["record"]["info"]["state_of_charge_pct"] == 100  # 127 would read as unknown
    assert "state_of_charge_pct" in _clamped(result)


def test_clamped_mavlink_output_passes_the_validator(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    record = {**VALID_UORB, "temperature": 400.0, "current_a": 3e36}
    _, (result,), _ = _convert(capsys, tmp_path, "uorb.BatteryStatus", "mavlink.BATTERY_STATUS", record)
    converted = tmp_path / "out.jsonl"
    converted.write_text(json.dumps(result["record"]) + "\n", encoding="utf-8")
    assert main(["validate", "--message", "mavlink.BATTERY_STATUS", str(converted)]) == 0, capsys.readouterr()


@pytest.mark.parametrize(
    ("source", "record", "said"),
    [
        (
            "mavlink.BATTERY_STATUS",
            {"current_battery": 70000},
            "current_battery = 70000 cA does not fit int16 (-32768..32767)",
        ),
        ("uorb.BatteryStatus", {"voltage_v": 12.0, "current_a": math.inf}, "current_a = inf is not a finite number"),
        ("uorb.BatteryStatus", {**VALID_UORB, "remaining": 2.0}, "remaining = 2 is above the maximum 1"),
        ("uorb.BatteryStatus", {**VALID_UORB, "voltage_v": math.nan}, "voltage_v is NaN, which is not allowed here"),
        ("mavlink.BATTERY_STATUS", {"battery_remaining": 101}, "battery_remaining = 101"),
    ],
)
def test_strict_refuses_what_validate_refuses(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, source: str, record: dict[str, Any], said: str
) -> None:
    target = "uorb.BatteryStatus" if source.startswith("mavlink") else "mavlink.BATTERY_STATUS"
    code, out, err = _convert(capsys, tmp_path, source, target, record)
    assert code == 2 and not out
    assert f"cannot convert (--policy strict): {said}" in err
    assert main(["validate", "--message", source, str(tmp_path / "in.jsonl")]) == 1
    assert said in capsys.readouterr().out


def _failsafe(capsys: pytest.CaptureFixture[str], tmp_path: Path, volts: float) -> str:
    params = tmp_path / "p.param"
    params.write_text("BATT_MONITOR 4\nBATT_LOW_VOLT 14.0\nBATT_CRT_VOLT 13.2\nBATT_FS_CRT_ACT 1\n", encoding="utf-8")
    samples = [(1, 16.0)] + [(t, volts) for t in range(2, 20)]
    log = tmp_path / "s.jsonl"
    log.write_text(
        "".join(
            json.dumps({"t": t, "armed": True, "data": {"voltage_v": v, "current_a": 1.0}}) + "\n" for t, v in samples
        ),
        encoding="utf-8",
    )
    assert main(["failsafe", "--message", "uorb.BatteryStatus", "--params", str(params), str(log)]) == 0
    captured = capsys.readouterr()
    return captured.out + captured.err


def test_the_failsafe_reads_a_voltage_as_its_float32_field_holds_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """5e-324 is 0.0 in uORB's float32 voltage_v, its unknown: ignored as 0.0 is, not a CRITICAL of 0.00 V."""
    tiny, zero, low = (_failsafe(capsys, tmp_path, v) for v in (5e-324, 0.0, 13.0))
    assert "0 events" in tiny and tiny.splitlines()[-1] == zero.splitlines()[-1]
    assert "CRITICAL" in low  # the same run with a real low voltage does fire


def test_the_export_leaves_out_a_float_beyond_its_type(tmp_path: Path) -> None:
    rows = [{"timestamp": 1_000_000 * i, "voltage_v": v} for i, v in enumerate([12.0, 1e300, 5e-324], 1)]
    log = tmp_path / "f.jsonl"
    log.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    (chunk,) = read_view(log, "f.jsonl", catalog=bundled_catalog(), message="uorb.BatteryStatus")
    assert chunk.n == 2 and chunk.batch.warnings == [
        "f.jsonl:2: voltage_v = 1e+300 does not fit float32 (+-3.40282e+38): record left out"
    ]
    assert list(chunk.batch.columns["voltage_v"]) == [12.0, 0.0]  # 5e-324 as the float32 field holds it


def test_an_infinite_value_is_clamped_and_said_so_like_a_finite_excess() -> None:
    """The runtime every converter stores integers through: +-inf clamps to the bounds and is reported."""
    from generated.convert import _runtime

    for x, expected in ((math.inf, 100), (-math.inf, 0), (1e300, 100), (-1e300, 0)):
        report = _runtime.LossReport()
        assert _runtime.to_int(x, 0, 100, report, "t.f") == expected
        assert [(e.kind, e.field) for e in report] == [("clamped", "t.f")]
