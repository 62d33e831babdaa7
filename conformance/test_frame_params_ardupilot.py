"""ArduPilot's own frame parameter files (../shared/corpus/upstream/ardupilot_frame_params, GPL-3.0, see
SOURCE.md), every layout: read as pymavlink's mavparm reads them, the vehicle told from the
parameters only it has, and ``battgen params --check`` agreeing with ``battgen validate``."""

from __future__ import annotations

from pathlib import Path

import pytest
from pymavlink import mavparm
from shared_data import UPSTREAM

from codegen.apps.failsafe.vehicles import detect_vehicle
from codegen.apps.gate.validate import check_file, make_checker
from codegen.apps.parameters.check import check_parameter_file
from codegen.apps.schemas.package import bundled_schemas
from codegen.inputs.parameters import files as parameter_files

CORPUS = UPSTREAM / "ardupilot_frame_params"
FILES = {
    "SPARKKit-rover.param": ("rover", False, 56),
    "SkyWalkerX8.param": ("plane", False, 116),
    "SkyViper-2450GPS/defaults.parm": ("copter", False, 176),
    "Sub/bluerov2-4_0_0.params": ("sub", False, 830),
    "TradHeli_Copter36_Setup-QGC.params": ("copter", True, 73),
}


@pytest.mark.parametrize("name", sorted(FILES))
def test_layout_values_and_vehicle(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    vehicle, qgc, count = FILES[name]
    path = CORPUS / name
    text = path.read_text(encoding="utf-8")
    assert parameter_files.is_qgc_text(text.splitlines()) is qgc
    [(_, values)] = list(parameter_files.read_parameter_file(path))
    assert len(values) == count
    assert detect_vehicle(values).vehicle.name == vehicle
    if not qgc:  # mavparm reads the ArduPilot layouts (NAME,VALUE and NAME VALUE) only
        reference = mavparm.MAVParmDict()
        assert reference.load(str(path), use_excludes=False)
        capsys.readouterr()
        assert set(values) == set(reference)
        for key, value in values.items():
            assert float(value) == pytest.approx(float(reference[key]), rel=0, abs=1e-12), key


@pytest.mark.parametrize("name", sorted(FILES))
def test_crlf_and_tabs_read_the_same(name: str, tmp_path: Path) -> None:
    path = CORPUS / name
    crlf = tmp_path / Path(name).name
    crlf.write_bytes(path.read_bytes().replace(b"\n", b"\r\n"))
    assert list(parameter_files.read_parameter_file(crlf)) == list(parameter_files.read_parameter_file(path))
    if not FILES[name][1]:  # NAME<TAB>VALUE is an ArduPilot layout too
        tabs = tmp_path / ("tabs-" + Path(name).name)
        tabs.write_text(path.read_text(encoding="utf-8").replace(",", "\t"), encoding="utf-8")
        assert list(parameter_files.read_parameter_file(tabs)) == list(parameter_files.read_parameter_file(path))


@pytest.mark.parametrize("name", sorted(FILES))
@pytest.mark.parametrize("vehicle", [None, "rover", "copter", "plane", "sub"])
def test_params_check_and_validate_agree(name: str, vehicle: str | None) -> None:
    path = CORPUS / name
    message, checker = make_checker(bundled_schemas(), "params.BATT", vehicle=vehicle)
    validated = check_file(path, message, checker, kind="param")
    checked = check_parameter_file(path, vehicle=vehicle)
    assert checked.unreadable is None and not validated.unreadable
    assert [(f.line, f.severity, f.message) for f in checked.findings] == [
        (f.line, f.severity, f.message) for f in validated.findings
    ]


def test_upstream_repeats_a_parameter_and_the_last_value_counts() -> None:
    """SkyViper-2450GPS/defaults.parm sets EK2_CHECK_SCALE twice (150, then 120): a vehicle loading
    it ends with 120 (so does mavparm); battgen reads it, keeps 120 and warns."""
    path = CORPUS / "SkyViper-2450GPS/defaults.parm"
    entries = parameter_files.load(path)
    [repeat] = parameter_files.repeats(entries)
    assert (repeat.name, repeat.values) == ("EK2_CHECK_SCALE", (150, 120))
    [(_, values)] = list(parameter_files.read_parameter_file(path))
    assert values["EK2_CHECK_SCALE"] == 120
    report = check_parameter_file(path)
    assert any("EK2_CHECK_SCALE is set 2 times" in note and "120" in note for note in report.notes)
    assert any("vehicle copter (detected from" in note for note in report.notes)
