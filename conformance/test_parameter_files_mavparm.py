"""Our .param reader against pymavlink's mavparm on the same files."""

from __future__ import annotations

from pathlib import Path

import pytest
from pymavlink import mavparm

from codegen.inputs.parameters import files as parameter_files

FILES = {
    "mission_planner.param": "BATT_CAPACITY,3300\nBATT_LOW_VOLT,10.5\nBATT_CRT_VOLT,10\nBATT_FS_LOW_ACT,2\n",
    "mavproxy.param": "BATT_CAPACITY    3300.000000\nBATT_LOW_VOLT    10.500000\nBATT_LOW_TIMER   10\n",
    "commented.param": "# header\n\nBATT_LOW_MAH,660 # trailing comment\n  BATT_CRT_MAH\t330\nBATT_OPTIONS,0x3\n",
    "ours.param": parameter_files.write_param(
        [("BATT_LOW_VOLT", 11.25, "OCV at 20 %"), ("BATT_CRT_VOLT", 11.04, "OCV at 10 %"), ("BATT_CAPACITY", 3300, "")],
        header=["proposed by battgen"],
    ),
}


@pytest.mark.parametrize("name", sorted(FILES))
def test_same_parameters_as_mavparm(tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / name
    path.write_text(FILES[name], encoding="utf-8")
    reference = mavparm.MAVParmDict()
    assert reference.load(str(path), use_excludes=False)
    capsys.readouterr()  # mavparm prints a summary
    [(_, ours)] = list(parameter_files.read_parameter_file(path))
    assert set(ours) == set(reference)
    for key, value in ours.items():
        assert float(value) == pytest.approx(float(reference[key]), rel=0, abs=1e-9), key
    assert len(ours) >= 3
