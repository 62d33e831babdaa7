"""Parameter files (.param / QGC .params), the cross-field checks and the devicetree proposal."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.apps.failsafe.checks import check_file, check_settings
from codegen.apps.parameters.proposal import propose, voltage_at
from codegen.errors import BattgenError
from codegen.inputs.parameters import files as parameter_files
from codegen.inputs.parameters.files import ParameterFileError

QGC = """# Onboard parameters for Vehicle 1
#
# Vehicle-Id Component-Id Name Value Type
1\t1\tBATT_CAPACITY\t3300\t6
1\t1\tBATT_LOW_VOLT\t10.500000000000000000\t9
1\t154\tMNT_TYPE\t1\t2
"""


def test_ardupilot_forms_and_comments(tmp_path: Path) -> None:
    path = tmp_path / "a.param"
    path.write_text(
        "# saved\nBATT_LOW_VOLT,10.5\nBATT_CRT_VOLT 10  # trailing\n\nBATT_OPTIONS\t0x3\n", encoding="utf-8"
    )
    entries = parameter_files.load(path)
    assert [(e.name, e.value, e.line) for e in entries] == [
        ("BATT_LOW_VOLT", 10.5, 2),
        ("BATT_CRT_VOLT", 10, 3),
        ("BATT_OPTIONS", 3, 5),
    ]
    assert list(parameter_files.read_parameter_file(path)) == [
        (2, {"BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10, "BATT_OPTIONS": 3})
    ]


def test_qgc_one_set_per_component(tmp_path: Path) -> None:
    path = tmp_path / "v.params"
    path.write_text(QGC, encoding="utf-8")
    sets = list(parameter_files.read_parameter_file(path))
    assert sets == [(4, {"BATT_CAPACITY": 3300, "BATT_LOW_VOLT": 10.5}), (6, {"MNT_TYPE": 1})]
    assert parameter_files.load(path)[1].mav_type == 9


def test_round_trip_and_select(tmp_path: Path) -> None:
    from generated.params import BattParams

    text = parameter_files.write_param([("BATT_LOW_VOLT", 10.5, "from the OCV table"), ("BATT_CAPACITY", 3300, "")])
    assert text == "BATT_LOW_VOLT,10.5  # from the OCV table\nBATT_CAPACITY,3300\n"
    qgc = parameter_files.write_qgc([("BATT_LOW_VOLT", 10.5, 9), ("BATT_CAPACITY", 3300, 6)])
    for name, body in (("r.param", text), ("r.params", qgc)):
        (tmp_path / name).write_text(body, encoding="utf-8")
        [(_, values)] = list(parameter_files.read_parameter_file(tmp_path / name))
        assert values == {"BATT_LOW_VOLT": 10.5, "BATT_CAPACITY": 3300}
    model = BattParams.from_dict(parameter_files.select({**values, "GPS_TYPE": 1}, BattParams))
    assert model.BATT_LOW_VOLT == 10.5


@pytest.mark.parametrize(
    ("name", "body", "line", "expected"),
    [
        ("a.param", "BATT_LOW_VOLT,10.5\nBATT_CRT_VOLT\n", 2, "expected 'NAME,VALUE' or 'NAME VALUE'"),
        ("a.param", "BATT_LOW_VOLT,ten\n", 1, "expected a number as the value"),
        ("a.param", "\nBATT_LOW_VOLT,nan\n", 2, "expected a finite number"),
        ("a.param", "BATT-LOW,1\n", 1, "expected a parameter name"),
        ("v.params", "# x\n1\t1\tBATT_A\t1\n", 2, "expected 5 tab-separated columns"),
        ("v.params", "1\t1\tBATT_A\t1\t9\n1\tx\tBATT_B\t1\t9\n", 2, "expected a decimal component id"),
        ("v.params", "1\t1\tBATT_A\t1\t11\n", 1, "expected a MAV_PARAM_TYPE from 1 to 10"),
        ("v.params", "1\t1\tBATT_A\t1.5\t6\n", 1, "expected an integer value"),
    ],
)
def test_errors_name_file_line_and_expectation(tmp_path: Path, name: str, body: str, line: int, expected: str) -> None:
    path = tmp_path / name
    path.write_text(body, encoding="utf-8")
    with pytest.raises(ParameterFileError) as info:
        parameter_files.load(path)
    assert (info.value.file, info.value.line) == (path.as_posix(), line)
    assert expected in info.value.message


def test_unreadable(tmp_path: Path) -> None:
    with pytest.raises(ParameterFileError, match="cannot read file"):
        parameter_files.load(tmp_path / "nope.param")
    (tmp_path / "b.param").write_bytes(b"BATT_A,1\n\xff\n")
    with pytest.raises(ParameterFileError, match=r"b\.param:2: expected UTF-8"):
        parameter_files.load(tmp_path / "b.param")


def findings(values: dict[str, float], **kw: object) -> list[tuple[str, str]]:
    return [(f.severity, f.param) for f in check_settings(values, **kw)]  # type: ignore[arg-type]


def test_cross_field_rules() -> None:
    ok = {"BATT_CAPACITY": 3300, "BATT_LOW_VOLT": 10.5, "BATT_CRT_VOLT": 10.0, "BATT_LOW_MAH": 660, "BATT_CRT_MAH": 330}
    assert findings(ok) == [] and findings(ok, cells=3) == []
    assert findings({}) == []  # everything 0: disabled, nothing to say
    # plausibility is a warning: ArduPilot flies with it (only its arming check objects to LOW < CRT)
    assert findings({**ok, "BATT_CRT_VOLT": 10.5}) == [("warning", "BATT_CRT_VOLT")]
    assert findings({**ok, "BATT_CRT_MAH": 700}) == [("warning", "BATT_CRT_MAH")]
    assert findings({**ok, "BATT_CAPACITY": 0}) == [("warning", "BATT_LOW_MAH"), ("warning", "BATT_CRT_MAH")]
    assert findings({**ok, "BATT_LOW_MAH": 4000, "BATT_CRT_MAH": 0}) == [("warning", "BATT_LOW_MAH")]
    assert findings({**ok, "BATT_LOW_MAH": -1, "BATT_CRT_MAH": 0}) == [("warning", "BATT_LOW_MAH")]
    assert findings({**ok, "BATT_LOW_TIMER": 0}) == [("warning", "BATT_LOW_TIMER")]  # disables the voltage checks
    # a 3S threshold on a 4S pack: 2.63 V per cell
    assert findings(ok, cells=4) == [("warning", "BATT_LOW_VOLT"), ("warning", "BATT_CRT_VOLT")]
    assert findings({"BATT_LOW_VOLT": 12.0}, cells=3, chemistry="life") == [("warning", "BATT_LOW_VOLT")]
    # no cell count puts 5 V and 4.5 V within 3.0..4.35 V per cell at once
    assert findings({"BATT_LOW_VOLT": 5.0, "BATT_CRT_VOLT": 4.5}) == [("warning", "BATT_LOW_VOLT")]
    assert findings({**ok, "BATT_ARM_VOLT": 10.4}) == [("warning", "BATT_ARM_VOLT")]
    # errors: what ArduPilot cannot act on, for every battery
    assert findings({"BATT2_FS_LOW_ACT": 7, "BATT3_FS_VOLTSRC": 2, "BATTG_LOW_TIMER": 200}) == [
        ("error", "BATT2_FS_LOW_ACT"),
        ("error", "BATT3_FS_VOLTSRC"),
        ("error", "BATTG_LOW_TIMER"),
    ]
    assert findings({"BATT5_LOW_VOLT": 10.0, "BATT5_CRT_VOLT": 10.2}) == [("warning", "BATT5_CRT_VOLT")]
    with pytest.raises(ValueError, match="expected a chemistry"):
        check_settings(ok, chemistry="coal")


def test_check_file_reports_parameter_lines(tmp_path: Path) -> None:
    path = tmp_path / "c.param"
    path.write_text("BATT_LOW_VOLT,10.5\n# note\nBATT_CRT_VOLT,11\n", encoding="utf-8")
    [(file, line, finding)] = check_file(path)
    assert (file, line, finding.param) == (path.as_posix(), 3, "BATT_CRT_VOLT")
    assert "is not below BATT_LOW_VOLT" in finding.message


def test_repeated_parameter_keeps_its_last_value(tmp_path: Path) -> None:
    path = tmp_path / "r.param"
    path.write_text("BATT_A,1\nBATT_B,5\r\nBATT_A,2\n", encoding="utf-8")
    assert list(parameter_files.read_parameter_file(path)) == [(1, {"BATT_A": 2, "BATT_B": 5})]
    [repeat] = parameter_files.repeats(parameter_files.load(path))
    assert (repeat.name, repeat.lines, repeat.values) == ("BATT_A", (1, 3), (1, 2))
    assert repeat.message() == "BATT_A is set 2 times (lines 1, 3): the last value, 2, is the one a vehicle loads"


def test_layout_from_content_not_extension(tmp_path: Path) -> None:
    comma = tmp_path / "ardupilot.params"  # ArduPilot's own .params files are comma-separated
    comma.write_text("BATT_LOW_VOLT,10.5\nBATT_CAPACITY,3300\n", encoding="utf-8")
    qgc = tmp_path / "qgc.param"
    qgc.write_text(QGC, encoding="utf-8")
    assert list(parameter_files.read_parameter_file(comma)) == [(1, {"BATT_LOW_VOLT": 10.5, "BATT_CAPACITY": 3300})]
    assert next(values for _, values in parameter_files.read_parameter_file(qgc)) == {
        "BATT_CAPACITY": 3300,
        "BATT_LOW_VOLT": 10.5,
    }


TABLE = [[4200000, 100], [3750000, 20], [3680000, 10], [3300000, 0]]


def test_proposal_from_battery_properties() -> None:
    props = {
        "device-chemistry": "lithium-ion-polymer",
        "charge-full-design-microamp-hours": [5000000],
        "voltage-max-design-microvolt": [[16800000]],
        "ocv-capacity-celsius": [0, 25],
        "ocv-capacity-table-0": [[4100000, 100], [3600000, 20], [3500000, 10], [3000000, 0]],
        "ocv-capacity-table-1": TABLE,
    }
    r = propose(props, where="b.dts:3", lines={"ocv-capacity-table-1": "b.dts:9"}, low_soc=15)
    assert r.cells == 4 and r.chemistry == "lipo"
    values = {p.name: p.value for p in r.proposals}
    assert values == {"BATT_CAPACITY": 5000, "BATT_LOW_VOLT": round(4 * 3.715, 2), "BATT_CRT_VOLT": 14.72}
    low = next(p for p in r.proposals if p.name == "BATT_LOW_VOLT")
    assert "OCV at 15 % SOC" in low.comment and "ocv-capacity-table-1, b.dts:9" in low.comment
    pack = propose(
        {"ocv-capacity-table-0": [[12600000, 100], [11100000, 20], [10800000, 10]]}, where="w", lines={}, cells=3
    )
    assert {p.name: p.value for p in pack.proposals} == {"BATT_LOW_VOLT": 11.1, "BATT_CRT_VOLT": 10.8}
    assert voltage_at([(4.2, 100), (3.0, 0)], 50) == pytest.approx(3.6)


@pytest.mark.parametrize(
    ("props", "kw", "expected"),
    [
        ({"ocv-capacity-table-0": TABLE}, {}, "nothing to propose .*give --cells"),
        ({"voltage-max-design-microvolt": [[8400000]]}, {}, "found neither: nothing to propose"),
        ({"device-chemistry": "plutonium", "ocv-capacity-table-0": TABLE}, {"cells": 1}, "expected a device-chemistry"),
        ({"ocv-capacity-table-0": [[4200000, 100], [3700000, 30]]}, {"cells": 1}, "outside the OCV table"),
        ({"ocv-capacity-table-0": TABLE}, {"cells": 1, "low_soc": 5.0}, "critical SOC < low SOC"),
    ],
)
def test_proposal_errors(props: dict[str, object], kw: dict[str, object], expected: str) -> None:
    with pytest.raises(BattgenError, match=expected):
        propose(props, where="b.dts:3", lines={}, **kw)  # type: ignore[arg-type]


def test_a_node_gets_what_it_supports_and_a_warning_for_the_rest() -> None:
    """Seed 004: a board's node without an OCV table (rk3399-pinebook-pro: 9.8 Ah) still gets BATT_CAPACITY; the
    binding's own example, whose tables cover 90..100 %, gets the capacity and a warning per voltage left out."""
    board = {"charge-full-design-microamp-hours": [[9800000]], "voltage-max-design-microvolt": [[4350000]]}
    r = propose(board, where="pinebook.dts:6", lines={})
    assert [(p.name, p.value) for p in r.proposals] == [("BATT_CAPACITY", 9800)]
    assert r.warnings == ("no ocv-capacity-table-N: BATT_LOW_VOLT and BATT_CRT_VOLT not proposed",)
    example = {
        "charge-full-design-microamp-hours": [[1430000]],
        "voltage-max-design-microvolt": [[4200000]],
        "ocv-capacity-table-0": [[4185000, 100], [4113000, 95], [4066000, 90]],
    }
    r = propose(example, where="example.dts:7", lines={"ocv-capacity-table-0": "example.dts:20"}, low_soc=95)
    assert {p.name: p.value for p in r.proposals} == {"BATT_CAPACITY": 1430, "BATT_LOW_VOLT": 4.11}
    (warning,) = r.warnings
    assert warning.startswith("BATT_CRT_VOLT not proposed: 10 % is outside the OCV table (90..100 %)")
    assert warning.endswith("(ocv-capacity-table-0, example.dts:20)")
