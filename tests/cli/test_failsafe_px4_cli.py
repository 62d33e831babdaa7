"""``battgen failsafe`` chooses the firmware (``--firmware``, the parameters', the log's) and prints PX4's events in
the format of ArduPilot's."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from shared_data import SHARED

from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "apps"))
from px4_flights import write_px4_flight

DESCENT = [0.5, 0.2, 0.14, 0.1, 0.06, 0.06, 0.04, 0.04]


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["failsafe", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_a_ulog_replays_through_px4_with_its_own_parameters(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = write_px4_flight(tmp_path / "f.ulg", DESCENT)
    code, out, err = run(capsys, str(log))
    assert code == 0
    assert "firmware px4 (the log is a PX4 ULog" in err and "BAT_LOW_THR 0.15" in err
    lines = out.splitlines()
    assert [ln.split()[4] for ln in lines] == ["LOW", "CRITICAL", "EMERGENCY"]
    # the ArduPilot line's layout: t, battery, level, cause, value, threshold, action (code) -> outcome, text
    assert lines[1].startswith("t=    10.800s  battery 1 CRITICAL charge   value=0.060 threshold=0.070 ")
    assert 'action=Warning (0) -> warn  "Critical battery level, land now"  uorb.warning=2' in lines[1]
    # the log's firmware logged no warning: the check says it differs, --strict makes that an exit 3
    assert "check battery 1 battery_status.warning: DIFFERS" in err
    assert run(capsys, "--strict", str(log))[0] == 3


def test_given_px4_parameters_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = write_px4_flight(tmp_path / "f.ulg", DESCENT)
    params = tmp_path / "px4.params"
    params.write_text("BAT_LOW_THR,0.3\nCOM_LOW_BAT_ACT,3\nCOM_FAIL_ACT_T,0\n", encoding="utf-8")
    code, out, err = run(capsys, "--json", "--params", str(params), str(log))
    assert code == 0 and f"{params} holds PX4's BAT_/COM_ parameters" in err
    events = [json.loads(x) for x in out.splitlines()]
    assert [(e["level"], e["action"], e["outcome"], e["firmware"]) for e in events] == [
        ("LOW", "Return or Land", "warn", "px4"),
        ("CRITICAL", "Return or Land", "rtl", "px4"),
        ("EMERGENCY", "Return or Land", "land", "px4"),
    ]
    assert events[0]["threshold"] == 0.3 and events[0]["t"] == pytest.approx(10.2)


def test_firmware_override_and_refusals(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = write_px4_flight(tmp_path / "f.ulg", DESCENT)
    params = tmp_path / "ap.param"
    params.write_text("BATT_LOW_VOLT,12.5\nBATT_LOW_TIMER,0.5\n", encoding="utf-8")
    code, out, err = run(capsys, "--params", str(params), str(log))  # ArduPilot's parameters: ArduPilot's failsafe
    assert code == 0 and "vehicle rover" in err and "battery 1 LOW      voltage" in out
    code, out, err = run(capsys, "--firmware", "px4", str(log))
    assert code == 0 and "firmware px4 (given" in err
    bin_log = SHARED / "corpus" / "realworld3" / "dataflash" / "dronekit_log171.bin"
    if bin_log.is_file():
        code, _, err = run(capsys, "--firmware", "px4", str(bin_log))
        assert code == 2 and "expected a PX4 ULog (.ulg)" in err
    empty = tmp_path / "nothing.ulg"
    write_px4_flight(empty, [])
    code, _, err = run(capsys, str(empty))
    assert code == 1 and "expected battery readings, found none (--allow-empty accepts that)" in err  # readable
    assert run(capsys, "--allow-empty", str(empty))[0] == 0


def test_firmware_choice_order(tmp_path: Path) -> None:
    from codegen.apps.failsafe.firmware import choose_firmware

    ulog, jsonl = write_px4_flight(tmp_path / "f.ulg", DESCENT), tmp_path / "s.jsonl"
    jsonl.write_text('{"t": 0, "armed": true, "battery": {"voltage_v": 12}}\n', encoding="utf-8")
    assert choose_firmware("ardupilot", {"BAT_LOW_THR": 0.2}, "p", ulog) == ("ardupilot", "given")
    assert choose_firmware(None, {"BATT2_LOW_VOLT": 10.0}, "p", ulog)[0] == "ardupilot"  # the parameters' firmware
    assert choose_firmware(None, {"COM_LOW_BAT_ACT": 2}, "p", jsonl)[0] == "px4"
    assert choose_firmware(None, {"SYSID_THISMAV": 1}, "p", ulog) == ("px4", "the log is a PX4 ULog")
    assert choose_firmware(None, None, "", jsonl)[0] == "ardupilot"
    with pytest.raises(ValueError, match="expected a firmware among px4, ardupilot"):
        choose_firmware("betaflight", None, "", jsonl)
