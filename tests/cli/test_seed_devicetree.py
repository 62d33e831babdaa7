"""Seed 004 end to end: the battery binding's own example and a board's node without an OCV table, through
``battgen params --from-devicetree`` (what each node supports is proposed, the rest named in a warning) and
``battgen convert`` reading the .dts and the .dtb dtc compiles from it."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from shared_data import SHARED, UPSTREAM, require

from codegen.cli.main import main


def _binding_example(folder: Path) -> Path:
    """The seed's example node as a .dts (the seed is a web page's copy: its blank lines hold no-break spaces,
    which dtc refuses as battgen does, so they are made spaces as a user pasting it would)."""
    (seed,) = require(SHARED / "seeds", "the seeds").glob("004_*")
    example = seed.read_text(encoding="utf-8").split("examples:\n  - |\n", 1)[1].replace("\u00a0", " ")
    path = folder / "binding-example.dts"
    path.write_text("/dts-v1/;\n/ {\n" + example + "};\n", encoding="utf-8")
    return path


def test_binding_example_gets_its_capacity_and_a_warning_per_voltage(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    dts = _binding_example(tmp_path)
    assert main(["params", "--from-devicetree", str(dts)]) == 0
    out, err = capsys.readouterr()
    assert [x for x in out.splitlines() if not x.startswith("#")] == [
        "BATT_CAPACITY,1430  # charge-full-design-microamp-hours = 1430000 uAh (charge-full-design-microamp-hours, "
        f"{dts.name}:14)"
    ]
    warnings = [x for x in err.splitlines() if ": warning: " in x]
    assert len(warnings) == 2  # LOW at 20 % and CRITICAL at 10 %: the tables cover 90..100 % only
    assert "BATT_LOW_VOLT not proposed: 20 % is outside the OCV table (90..100 %)" in warnings[0]
    assert "BATT_CRT_VOLT not proposed: 10 % is outside the OCV table (90..100 %)" in warnings[1]
    # thresholds the table does reach are proposed from it
    assert main(["params", "--from-devicetree", str(dts), "--low-soc", "95", "--critical-soc", "92"]) == 0
    values = dict(x.split("  #")[0].split(",") for x in capsys.readouterr().out.splitlines() if not x[0] == "#")
    # ocv-capacity-table-2 (10 degC, the nearest 20 degC): 4.2 V at 95 %, 4.185 V at 90 %
    assert values == {"BATT_CAPACITY": "1430", "BATT_LOW_VOLT": "4.2", "BATT_CRT_VOLT": "4.19"}


def test_board_without_an_ocv_table_gets_its_capacity(capsys: pytest.CaptureFixture[str]) -> None:
    board = require(UPSTREAM / "linux_batteries" / "rk3399-pinebook-pro.dts")
    assert main(["params", "--from-devicetree", str(board)]) == 0
    out, err = capsys.readouterr()
    assert [x.split("  #")[0] for x in out.splitlines() if not x.startswith("#")] == ["BATT_CAPACITY,9800"]
    assert "no ocv-capacity-table-N: BATT_LOW_VOLT and BATT_CRT_VOLT not proposed" in err


@pytest.mark.skipif(shutil.which("dtc") is None, reason="dtc (Debian's device-tree-compiler) compiles the .dtb")
def test_convert_reads_dts_and_dtb(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dts = _binding_example(tmp_path)
    dtb = tmp_path / "binding-example.dtb"
    subprocess.run(["dtc", "-I", "dts", "-O", "dtb", "-o", str(dtb), str(dts)], check=True, capture_output=True)
    for source in (dts, dtb):
        argv = ["convert", "--from", "devicetree", "--to", "uorb", "--set", "ocv_v=4.19", "--set", "temperature_c=10"]
        assert main([*argv, str(source)]) == 0
        (record,) = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
        # the kernel's power_supply_ocv2cap_simple on ocv-capacity-table-2: 90 + 5 * 5000 // 15000 = 91 %
        assert record["remaining"] == pytest.approx(0.91) and record["capacity"] == 1430
