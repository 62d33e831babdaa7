"""``battgen failsafe`` and ``battgen params`` end to end through the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main

# a Rover's 3S pack: LOW 10.5 V -> 1 (RTL on Rover), CRITICAL 10.0 V -> 2 (Hold on Rover)
PARAMS = "BATT_LOW_VOLT,10.5\nBATT_CRT_VOLT,10.0\nBATT_FS_LOW_ACT,1\nBATT_FS_CRT_ACT,2\n"
DTS = """/dts-v1/;
/ {
\tbattery: battery {
\t\tcompatible = "simple-battery";
\t\tdevice-chemistry = "lithium-ion-polymer";
\t\tcharge-full-design-microamp-hours = <3300000>;
\t\tvoltage-max-design-microvolt = <12600000>;
\t\tocv-capacity-celsius = <20>;
\t\tocv-capacity-table-0 = <4200000 100>, <3750000 20>, <3680000 10>, <3300000 0>;
\t};
};
"""


def sample(t: float, volts: float) -> dict[str, object]:
    """Alternate the formats: uORB, MAVLink (mV in cell 0) and SI values."""
    if t % 3 == 0:
        return {"t": t, "armed": True, "message": "uorb.BatteryStatus", "data": {"voltage_v": volts}}
    if t % 3 == 1:
        cells = [round(volts * 1000)] + [65535] * 9
        return {"t": t, "armed": True, "message": "BATTERY_STATUS", "data": {"voltages": cells}}
    return {"t": t, "armed": True, "battery": {"voltage_v": volts}}


def write_stream(path: Path, rows: list[dict[str, object]]) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    return path


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    params = tmp_path / "fs.param"
    params.write_text(PARAMS, encoding="utf-8")
    rows = [sample(t, 11.5 if t < 5 else 10.4 if t < 25 else 9.8) for t in range(40)]
    return params, write_stream(tmp_path / "s.jsonl", rows)


def test_timeline_from_mixed_formats(files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    params, stream = files
    assert main(["failsafe", "--params", str(params), str(stream)]) == 0
    captured = capsys.readouterr()
    out = captured.out.splitlines()
    assert len(out) == 2
    # below 10.5 V from t = 5: LOW once more than BATT_LOW_TIMER (10 s) has passed, at t = 16
    assert out[0].startswith("t=    16.000s  battery 1 LOW ") and "action=RTL (1) -> rtl" in out[0]
    assert '"Battery 1 is low 10.40V used 0 mAh"' in out[0] and 'seed: "Battery LOW: 10.4V"' in out[0]
    assert "uorb.warning=1 mavlink.charge_state=2" in out[0]
    # below 10.0 V from t = 25: CRITICAL timed too, at t = 36; Hold outranks RTL, so it runs
    assert out[1].startswith("t=    36.000s  battery 1 CRITICAL") and "action=Hold (2) -> hold" in out[1]
    assert '"Battery 1 is critical 9.80V used 0 mAh"' in out[1] and "(line 37)" in out[1]
    assert "vehicle rover (assumed: no parameter only one vehicle has; give --vehicle)" in captured.err


def test_json_events_carry_the_level_in_the_converted_message(
    files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    params, stream = files
    assert main(["failsafe", "--params", str(params), "--no-home", "--json", str(stream)]) == 0
    low, crit = (json.loads(line) for line in capsys.readouterr().out.splitlines())
    assert {k: low[k] for k in ("t", "battery", "level", "cause", "value", "threshold")} == {
        "t": 16.0, "battery": 1, "level": "LOW", "cause": "voltage", "value": 10.4, "threshold": 10.5
    }  # fmt: skip
    assert (low["action"], low["action_code"], low["executed"], low["outcome"]) == ("RTL", 1, True, "hold")
    assert (low["seed_text"], low["ardupilot_text"]) == ("Battery LOW: 10.4V", "Battery 1 is low 10.40V used 0 mAh")
    # t = 16 was a MAVLink BATTERY_STATUS, t = 36 a uORB battery_status: each comes back with the level
    assert (low["message"], low["data"]["charge_state"]) == ("mavlink.BATTERY_STATUS", low["mavlink_charge_state"])
    assert (crit["t"], crit["message"], crit["data"]["warning"]) == (36.0, "uorb.BatteryStatus", crit["uorb_warning"])
    assert crit["mavlink_charge_state"] == 3 and crit["executed"] and crit["outcome"] == "hold"


@pytest.mark.parametrize(
    ("line", "expected"),
    [
        ('{"t": 1, "armed": tru}', "s.jsonl:2: expected one JSON object per line"),
        ('{"t": "x", "armed": true, "battery": {}}', 's.jsonl:2: expected "t": a number of seconds'),
        ('{"t": 1, "armed": 1, "battery": {}}', 's.jsonl:2: expected "armed": true or false'),
        ('{"t": 1, "armed": true, "data": {}}', 's.jsonl:2: expected "message"'),
        ('{"t": 1, "armed": true, "message": "NoSuch", "data": {}}', "s.jsonl:2: no message called 'NoSuch'"),
        ('{"t": 1, "armed": true, "message": "uorb.BatteryStatus", "data": {"voltage_v": "x"}}', "voltage_v"),
        ('{"t": 0.5, "armed": true, "battery": {}}', "s.jsonl: line 2: expected sample times that never go back"),
        ('{"t": 2, "armed": true, "instance": 17, "battery": {}}', 's.jsonl:2: expected "instance": a battery number'),
    ],
)
def test_unreadable_stream_exits_2(
    tmp_path: Path, files: tuple[Path, Path], capsys: pytest.CaptureFixture[str], line: str, expected: str
) -> None:
    params, _ = files
    stream = tmp_path / "s.jsonl"
    stream.write_text('{"t": 1, "armed": true, "battery": {"voltage_v": 12}}\n' + line + "\n", encoding="utf-8")
    assert main(["failsafe", "--params", str(params), str(stream)]) == 2
    assert expected in capsys.readouterr().err


def test_unreadable_params_exit_2(tmp_path: Path, files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    _, stream = files
    bad = tmp_path / "bad.param"
    bad.write_text("BATT_LOW_VOLT\n", encoding="utf-8")
    assert main(["failsafe", "--params", str(bad), str(stream)]) == 2
    assert "bad.param:1: expected 'NAME,VALUE' or 'NAME VALUE'" in capsys.readouterr().err


def test_params_from_devicetree_writes_commented_param_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dts = tmp_path / "bat.dts"
    dts.write_text(DTS, encoding="utf-8")
    out = tmp_path / "proposed.param"
    assert main(["params", "--from-devicetree", str(dts), "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert "BATT_CAPACITY,3300  # charge-full-design-microamp-hours = 3300000 uAh" in text
    assert (
        "BATT_LOW_VOLT,11.25  # OCV at 20 % SOC: 3.750 V per cell x 3 cells (ocv-capacity-table-0, bat.dts:9)" in text
    )
    assert "BATT_CRT_VOLT,11.04  # OCV at 10 % SOC" in text
    assert "3 cells: voltage-max-design 12.6 V / 4.2 V per cell" in text
    # the proposal is a valid parameter set: --check passes, and the evaluator reads it
    assert main(["params", "--check", str(out)]) == 0
    assert main(["params", "--from-devicetree", str(dts), "--cells", "4", "--low-soc", "15"]) == 0
    assert "BATT_LOW_VOLT,14.86" in capsys.readouterr().out


def test_params_check_reports_lines(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "v.param"
    path.write_text(
        "BATT_LOW_VOLT,10.5\nBATT_CRT_VOLT,11\nBATT_LOW_TIMER,200\nGPS_TYPE,1\nBATT2_FS_LOW_ACT,6\n", encoding="utf-8"
    )
    assert main(["params", "--check", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path.as_posix()}:3: error: BATT_LOW_TIMER = 200 s does not fit int8" in out  # AP_Int8
    assert f"{path.as_posix()}:2: warning: BATT_CRT_VOLT (11 V) is not below BATT_LOW_VOLT (10.5 V)" in out
    assert f"{path.as_posix()}:5: error: BATT2_FS_LOW_ACT = 6 is no rover action" in out
    assert main(["params", "--check", str(path), "--vehicle", "copter"]) == 1  # 6 is Copter's; the timer is not
    assert "BATT2_FS_LOW_ACT" not in capsys.readouterr().out


def test_params_from_devicetree_without_battery(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dts = tmp_path / "empty.dts"
    dts.write_text("/dts-v1/;\n/ {\n};\n", encoding="utf-8")
    assert main(["params", "--from-devicetree", str(dts)]) == 2
    assert 'expected a compatible = "simple-battery" node' in capsys.readouterr().err


def test_repeated_parameter_warns_and_the_last_value_counts(
    tmp_path: Path, files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    _, stream = files
    params = tmp_path / "twice.param"
    params.write_text("BATT_LOW_VOLT,9\r\nBATT_FS_LOW_ACT,2\r\nBATT_LOW_VOLT,10.5\r\n", encoding="utf-8")
    assert main(["failsafe", "--params", str(params), str(stream)]) == 0
    captured = capsys.readouterr()
    assert "twice.param:3: BATT_LOW_VOLT is set 2 times (lines 1, 3): the last value, 10.5" in captured.err
    assert captured.out.startswith("t=    16.000s  battery 1 LOW ")  # 10.5 V, not 9 V
