"""The battgen command line: commands, exit codes, and errors without tracebacks."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.cli.main import main
from codegen.ir.json_form import validate_ir_json

SCHEMAS = ROOT / "schemas"


def run(args: list[str], cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "codegen", *args], cwd=cwd, capture_output=True, text=True, check=False
    )


def test_list_prints_qualified_names(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["list", str(SCHEMAS)]) == 0
    names = capsys.readouterr().out.split()
    for expected in (
        "uorb.BatteryStatusV0",
        "uorb.BatteryStatus",
        "dronecan.uavcan.equipment.power.BatteryInfo",
        "dronecan.uavcan.equipment.power.CircuitStatus",
        "dronecan.uavcan.equipment.power.PrimaryPowerSupplyStatus",
        "dronecan.ardupilot.equipment.power.BatteryInfoAux",
        "dronecan.uavcan.Timestamp",
        "mavlink.BATTERY_STATUS",
        "devicetree.power.supply.battery",
    ):
        assert expected in names
    assert names == sorted(names)


def test_ir_is_valid_json_against_the_ir_schema(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ir", str(SCHEMAS)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert validate_ir_json(data) == []
    assert {m["format"] for m in data["messages"]} == {"uorb", "dronecan", "devicetree", "mavlink", "params", "cyphal"}


@pytest.mark.parametrize(
    "rel",
    [
        "uorb/BatteryStatus.msg",
        "dronecan/uavcan/equipment/power/1092.BatteryInfo.uavcan",
        "mavlink/battery.xml",
        "devicetree/power/supply/battery.yaml",
    ],
)
def test_ir_of_single_files(rel: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ir", str(SCHEMAS / rel)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["messages"] and validate_ir_json(data) == []


def test_generate_out_writes_an_importable_package(tmp_path: Path) -> None:
    out = tmp_path / "mybatt"
    proc = run(["generate", str(SCHEMAS), "--out", str(out)])
    assert proc.returncode == 0, proc.stderr
    assert "generated" in proc.stdout and "wrote" in proc.stdout
    check = subprocess.run(
        [
            sys.executable,
            "-c",
            "import mybatt.uorb, mybatt.mavlink, mybatt.devicetree; "
            "from mybatt.dronecan.uavcan.equipment.power import BatteryInfo; print(BatteryInfo().to_dict())",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert check.returncode == 0, check.stderr
    again = run(["generate", str(SCHEMAS), "--out", str(out), "--check"])
    assert again.returncode == 0 and "up to date" in again.stdout


def test_check_names_stale_and_extra_files(tmp_path: Path) -> None:
    out = tmp_path / "pkg"
    assert run(["generate", str(SCHEMAS), "--out", str(out)]).returncode == 0
    (out / "uorb.py").write_text("# edited\n")
    (out / "leftover.py").write_text("")
    proc = run(["generate", str(SCHEMAS), "--out", str(out), "--check"])
    assert proc.returncode == 1
    assert "uorb.py" in proc.stderr and "leftover.py" in proc.stderr
    assert (out / "uorb.py").read_text() == "# edited\n"  # --check writes nothing


def test_malformed_schema_exits_2_without_traceback(tmp_path: Path) -> None:
    bad = tmp_path / "Bad.msg"
    bad.write_text("uint8 ok\nfloat99 broken\n")
    proc = run(["ir", str(bad)])
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "Bad.msg:2" in proc.stderr


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["ir", "/nonexistent/file.msg"], "no such file"),
        (["ir", "README.md"], "extension"),
        (["list", "tests"], "not a schema folder"),
        (["generate", "--out", "/tmp/not-an-ident-"], "identifier"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_usage_errors_exit_2(args: list[str], needle: str) -> None:
    proc = run(args)
    assert proc.returncode == 2
    assert needle in proc.stderr and "Traceback" not in proc.stderr


def test_missing_dependency_is_a_clean_error(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import codegen.cli.main as cli

    def missing(_: object) -> int:
        raise ModuleNotFoundError("No module named 'pymavlink'", name="pymavlink")

    monkeypatch.setattr(cli, "cmd_list", missing)
    assert cli.main(["list"]) == 2
    err = capsys.readouterr().err
    assert "needs the Python package 'pymavlink'" in err and "Traceback" not in err
