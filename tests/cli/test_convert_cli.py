"""``battgen convert``: formats in and out, streaming, loss reports, and clear errors (exit 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from codegen.cli.main import main
from generated.mavlink import BatteryStatus as MavBatteryStatus

RECORD = {"temperature": 298.15, "voltage": 12.6, "current": 5, "state_of_charge_pct": 127, "battery_id": 0}


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_jsonl_px4_pins_the_issue_cases(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text(json.dumps(RECORD) + "\n\n" + json.dumps(RECORD | {"battery_id": 3}) + "\n")
    code, out, err = run(capsys, "convert", "--from", "dronecan", "--to", "mavlink", "--policy", "px4", str(src))
    assert code == 0, err
    first, second = (json.loads(line) for line in out.splitlines())
    assert (first["id"], first["temperature"], first["battery_remaining"]) == (255, 2510, 127)
    assert second["id"] == 2


def test_strict_default_and_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.json"
    src.write_text(json.dumps(RECORD))
    out_file = tmp_path / "out.json"
    code, _, err = run(
        capsys, "convert", "--from", "dronecan", "--to", "uorb", "--report", str(src), "-o", str(out_file)
    )
    assert code == 0, err
    data = json.loads(out_file.read_text())
    assert data["record"]["remaining"] == -1.0 and data["record"]["id"] == 1
    assert data["record"]["time_remaining_s"] == "NaN"
    assert {"kind": "unknown", "field": "uorb.BatteryStatus.remaining"} in data["loss"]


def test_yaml_in_and_out_with_a_multi_message_side(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.yaml"
    src.write_text(yaml.safe_dump([{"info": {"voltage": 11.1}, "aux": {"voltage_cell": [3.7, 3.7, 3.7]}}]))
    code, out, err = run(capsys, "convert", "--from", "dronecan", "--to", "uorb", str(src))
    assert code == 0, err
    data = yaml.safe_load(out)
    assert data["cell_count"] == 3 and data["voltage_cell_v"][:3] == [pytest.approx(3.7)] * 3
    back = tmp_path / "uorb.json"
    back.write_text(json.dumps({"voltage_v": 11.1, "id": 2, "max_error": 1}))  # a record validate accepts
    code, out, err = run(capsys, "convert", "--from", "uorb", "--to", "dronecan", "--out-format", "yaml", str(back))
    assert code == 0, err
    data = yaml.safe_load(out)
    assert data["info"]["battery_id"] == 1 and data["aux"]["battery_id"] == 1


def test_hex_payloads_through_the_codecs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    if not hasattr(MavBatteryStatus, "decode"):
        pytest.skip("MAVLink codec not generated")
    payload = MavBatteryStatus(id=0, temperature=2510, voltages=[12600] + [65535] * 9).encode()
    src = tmp_path / "in.hex"
    src.write_text(payload.hex() + "\n")
    code, out, err = run(capsys, "convert", "--from", "mavlink", "--to", "uorb", "--policy", "px4", str(src))
    assert code == 0, err
    record = json.loads(out)
    assert record["voltage_v"] == pytest.approx(12.6) and record["temperature"] == 2510.0  # PX4 copies cdegC
    src2 = tmp_path / "in2.jsonl"
    src2.write_text(json.dumps({"voltage_v": 12.6, "connected": True, "id": 1}) + "\n")
    code, out, err = run(
        capsys, "convert", "--from", "uorb", "--to", "mavlink", "--policy", "px4", "--out-format", "hex", str(src2)
    )
    assert code == 0, err
    assert MavBatteryStatus.decode(bytes.fromhex(out.strip())).voltages[0] == 12600


def test_devicetree_inputs_with_set(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    node = {
        "compatible": ["simple-battery"],
        "ocv-capacity-celsius": [20],
        "ocv-capacity-table-0": [[4200000, 100], [3600000, 0]],
    }
    src = tmp_path / "node.json"
    src.write_text(json.dumps(node))
    code, out, err = run(capsys, "convert", "--from", "devicetree", "--to", "uorb", "--set", "ocv_v=3.9", str(src))
    assert code == 0, err
    assert json.loads(out)["remaining"] == pytest.approx(0.5)
    code, _, err = run(capsys, "convert", "--from", "devicetree", "--to", "uorb", "--set", "volts=3.9", str(src))
    assert code == 2 and "--set volts: not an input of devicetree -> uorb (ocv_v, temperature_c)" in err


def test_unknown_pair_is_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "convert", "--from", "dronecan", "--to", "canbus", "/dev/null")
    assert code == 2 and "--to 'canbus': expected a format or message" in err and "Traceback" not in err
    code, _, err = run(capsys, "convert", "--from", "dronecn", "--to", "uorb", "/dev/null")  # a short hint, one line
    assert code == 2 and err.strip().endswith("did you mean 'dronecan'?") and len(err) < 200


def test_px4_where_px4_has_no_code_path_is_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "convert", "--from", "devicetree", "--to", "uorb", "--policy", "px4", "/dev/null")
    assert code == 2 and "has no px4 policy" in err


def test_invalid_record_names_its_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text(json.dumps(RECORD) + "\n" + json.dumps({"voltage": "twelve"}) + "\n")
    code, out, err = run(capsys, "convert", "--from", "dronecan", "--to", "uorb", str(src))
    assert code == 2 and f"{src}:2: invalid dronecan record" in err and "voltage" in err
    assert len(out.splitlines()) == 1  # the first record was already streamed out


def test_malformed_json_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text('{"voltage": 1}\n{"voltage": \n')
    code, _, err = run(capsys, "convert", "--from", "dronecan", "--to", "uorb", str(src))
    assert code == 2 and f"{src}:2: expected one JSON record per line" in err


def test_a_record_lacking_its_required_message(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text(json.dumps({"aux": {"voltage_cell": [3.7]}}) + "\n")
    code, _, err = run(capsys, "convert", "--from", "dronecan", "--to", "uorb", str(src))
    assert code == 2 and f"{src}:1: expected the info message of dronecan" in err


def test_a_conversion_needing_a_value_the_input_lacks(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.jsonl"
    src.write_text(json.dumps({"voltage_cell_v": [3.7] * 13}) + "\n")
    code, _, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(src))
    assert code == 2 and f"{src}:1: invalid uorb record" in err and "14" in err


def test_bad_hex_and_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.hex"
    src.write_text("zz\n")
    code, _, err = run(capsys, "convert", "--from", "mavlink", "--to", "uorb", str(src))
    assert code == 2 and f"{src}:1: expected hexadecimal payloads" in err
    code, _, err = run(capsys, "convert", "--from", "mavlink", "--to", "uorb", str(tmp_path / "nope.json"))
    assert code == 2 and "cannot read" in err
