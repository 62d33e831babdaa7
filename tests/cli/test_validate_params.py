"""`battgen validate` on parameter files: ArduPilot .param and QGroundControl .params.

One record per parameter set; violations name the parameter's line; the failsafe cross-field
checks are reported once (not again where the schema's range already caught the value)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from codegen.cli.main import main


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[str], str]:
    code = main(["validate", *args])
    out, err = capsys.readouterr()
    return code, [line for line in out.splitlines() if line], err


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict[str, Any]]:
    code = main(["validate", "--format", "json", *args])
    return code, json.loads(capsys.readouterr().out)


PARAM = """\
# saved by Mission Planner
ARMING_CHECK,1
BATT_CAPACITY,3300
BATT_LOW_VOLT,10.5
BATT_CRT_VOLT,-1
BATT_LOW_MAH,4000   # above the capacity
BATT_FS_LOW_ACT,9
"""


def test_param_file_violations_point_at_parameter_lines(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "vehicle.param"
    path.write_text(PARAM, encoding="utf-8")
    code, lines, err = run(capsys, str(path))  # --message omitted: params.BATT
    assert code == 1
    by_line = {int(line.split(":")[1]): line for line in lines}
    assert set(by_line) == {5, 6, 7}, lines
    # ArduPilot treats a negative threshold as off, and flies with a LOW_MAH above the capacity:
    # warnings; 9 is no Rover action: an error
    assert "warning: BATT_CRT_VOLT is -1: ArduPilot treats a negative value as 0 (off)" in by_line[5]
    assert "warning: BATT_LOW_MAH (4000 mAh) is not below BATT_CAPACITY" in by_line[6]
    assert "BATT_FS_LOW_ACT = 9 is no rover action" in by_line[7] and "warning" not in by_line[7]
    assert len(lines) == 3
    assert "params.BATT: 1 record in 1 file, 1 error, 2 warnings" in err


def test_negative_threshold_without_a_schema_range_comes_from_check_params(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "neg.param"
    path.write_text("BATT_CAPACITY 3300\nBATT_CRT_MAH -5\n", encoding="utf-8")
    code, doc = run_json(capsys, "--message", "params.BATT", str(path))
    assert code == 0  # a warning
    [violation] = doc["files"][0]["violations"]
    assert (violation["line"], violation["path"], violation["rule"]) == (2, "BATT_CRT_MAH", "cross-field:failsafe")
    assert violation["severity"] == "warning"


def test_mavproxy_style_float_values_fit_integer_parameters(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "mavproxy.parm"
    path.write_text("BATT_CAPACITY    5000.000000\nBATT_LOW_TIMER   10.000000\n", encoding="utf-8")
    code, lines, err = run(capsys, str(path))
    assert (code, lines) == (0, []), err


def test_qgc_file_one_record_per_component_with_location(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "vehicle.params"
    path.write_text(
        "# Onboard parameters\n# Vehicle-Id Component-Id Name Value Type\n"
        "1\t1\tBATT_LOW_VOLT\t10.5\t9\n1\t1\tBATT_CRT_VOLT\t11\t9\n"
        "1\t154\tMNT_TYPE\t1\t2\n"  # a gimbal: nothing of params.BATT
        "2\t1\tBATT_LOW_TIMER\t200\t2\n",
        encoding="utf-8",
    )
    code, doc = run_json(capsys, str(path))
    assert code == 1
    report = doc["files"][0]
    assert report["records"] == 2
    found = {(v["line"], v["path"], v["location"]["vehicle"], v["location"]["component"]) for v in report["violations"]}
    assert found == {(4, "BATT_CRT_VOLT", 1, 1), (6, "BATT_LOW_TIMER", 2, 1)}


def test_file_without_the_message_parameters_is_a_notice(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "other.param"
    path.write_text("ARMING_CHECK,1\nSERIAL0_BAUD,115\n", encoding="utf-8")
    code, lines, err = run(capsys, str(path))
    assert (code, lines) == (1, [])  # a parameter file without the parameters asked for is not a pass
    assert "warning: no parameter of params.BATT in this file (2 parameters read)" in err
    assert "0 records" in err and "no params.BATT records in this file" in err


def test_malformed_param_file_exits_2_naming_file_and_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "bad.param"
    path.write_text("BATT_CAPACITY,3300\nBATT_LOW_VOLT,ten\n", encoding="utf-8")
    code, lines, err = run(capsys, str(path))
    assert code == 2 and lines == []
    assert f"{path.as_posix()}:2: expected a number as the value, got 'ten'" in err
    assert "Traceback" not in err


def test_message_must_match_parameter_files(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "v.param"
    path.write_text("BATT_CAPACITY,3300\n", encoding="utf-8")
    code, _, err = run(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 2 and "a parameter file holds parameters, but uorb.BatteryStatus is a uorb message" in err


def test_message_is_required_where_no_default_exists(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "r.json"
    path.write_text("{}", encoding="utf-8")
    assert main(["validate", str(path)]) == 2
    assert "--message is required" in capsys.readouterr().err
    log = tmp_path / "x.jsonl"
    log.write_text('{"voltage_v": 12.0}\n', encoding="utf-8")
    assert main(["validate", str(log)]) == 2  # plain records of any format: which message?
    assert "--message is required" in capsys.readouterr().err


def test_a_log_defaults_to_its_battery_message(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    # a ULog holds battery_status, whatever older versions of the message the schemas also hold: the message the
    # report and the export read it as (one table, codegen.apps.schemas.messages.BATTERY_MESSAGES)
    log = tmp_path / "x.ulg"
    log.write_bytes(b"")
    assert main(["validate", str(log)]) == 2
    err = capsys.readouterr().err
    assert "--message is required" not in err and "empty file" in err
    dataflash = tmp_path / "x.bin"
    dataflash.write_bytes(b"\xa3\x95\x80")
    assert main(["validate", str(dataflash)]) == 2
    assert "have no message schema" in capsys.readouterr().err


def test_json_params_records_get_the_cross_field_checks_too(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "p.json"
    path.write_text(json.dumps({"BATT_LOW_VOLT": 10.0, "BATT_CRT_VOLT": 10.5}), encoding="utf-8")
    code, lines, _ = run(capsys, "--message", "params.BATT", str(path))
    assert code == 0 and len(lines) == 1 and "warning: BATT_CRT_VOLT (10.5 V) is not below BATT_LOW_VOLT" in lines[0]


def test_vehicle_decides_the_action_codes(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "copter.param"
    path.write_text("BATT_FS_LOW_ACT,6\nBATT2_FS_CRT_ACT,6\nBATT2_LOW_VOLT,10.5\n", encoding="utf-8")
    code, lines, _ = run(capsys, str(path))  # rover assumed: 6 is none of its actions
    assert code == 1 and [line.split(":")[1] for line in lines] == ["1", "2"]
    assert "BATT2_FS_CRT_ACT = 6 is no rover action" in lines[1]
    assert run(capsys, "--vehicle", "copter", str(path))[0] == 0  # Auto DO_LAND_START or RTL
    path.write_text("RTL_ALT,1500\nBATT_FS_LOW_ACT,6\n", encoding="utf-8")  # RTL_ALT: only Copter has it
    assert run(capsys, str(path))[0] == 0
    assert run(capsys, "--vehicle", "sub", str(path))[0] == 1
