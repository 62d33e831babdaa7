"""Every problem of a devicetree node in one report (codegen.apps.gate.devicetree through battgen validate).

The same cases are compared with dt-validate itself in conformance/test_dt_node_problems_dtschema.py;
these run without dtc or dtschema and pin the wording, lines and exit code."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from codegen.cli.main import main

NODE = """/dts-v1/;
/ {
\tbattery {
\t\tcompatible = "simple-battery";
\t\tacme,secret-sauce = <1>;
\t\tother-sauce-microvolt = <2>;
\t\tocv-capacity-celsius = <20>;
\t\tocv-capacity-table-0 = <4200000 101>, <3700000 50>, <3300000 0>;
\t\tocv-capacity-table-1 = <4200000 102>, <3700000>, <3300000 103>;
\t};
};
"""


def test_every_problem_of_a_node_in_dt_validates_order(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    board = tmp_path / "board.dts"
    board.write_text(NODE)
    code = main(["validate", "--message", "simple-battery", "--format", "json", str(board)])
    (report,) = json.loads(capsys.readouterr().out)["files"]
    found = [v for v in report["violations"] if v["node"] == "/battery"]
    problems = [v["message"] for v in found]
    assert code == 1
    assert problems[0] == (
        "acme,secret-sauce, other-sauce-microvolt are not defined by devicetree.power.supply.battery "
        "(additionalProperties: false)"
    )
    assert found[0]["value"] == ["acme,secret-sauce", "other-sauce-microvolt"]
    # the pattern properties item by item, as dt-validate cuts the cells (5 cells: rows of 2, then [103]);
    # the short row is reported and the rows around it are still checked
    assert [v["path"] for v in found[1:5]] == [
        "ocv-capacity-table-0[0][1]",
        "ocv-capacity-table-1[0][1]",
        "ocv-capacity-table-1[1][1]",
        "ocv-capacity-table-1[2]",
    ]
    assert problems[5] == "acme,secret-sauce: no schema gives this property a type, so its value stays raw bytes"
    assert len(problems) == 6 and [v["line"] for v in found] == [5, 8, 9, 9, 9, 5]  # each at its property's line


def test_long_and_many_property_names_are_named_briefly(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A JSON record's keys are unbounded: a 4,400-digit unknown key (a random fuzz find) and a pattern property
    of that length are clipped to head and tail, and 30 unknown keys are named 8 at a time with a count."""
    digits = "9" * 4400
    record = {
        "compatible": ["simple-battery"],
        digits + "voltage_v": 16.4,
        **{f"unknown-{i:02}": 1 for i in range(30)},
        "ocv-capacity-celsius": [20],
        "ocv-capacity-table-" + digits: [["x", 100]],
    }
    data = tmp_path / "battery.json"
    data.write_text(json.dumps(record))
    code = main(["validate", "--message", "devicetree.power.supply.battery", "--format", "json", str(data)])
    (report,) = json.loads(capsys.readouterr().out)["files"]
    messages = [v["message"] for v in report["violations"]]
    assert code == 1 and messages
    assert max(len(m) for m in messages) < 400, [m[:200] for m in messages]
    unknown = messages[0]
    assert unknown.startswith("999") and "999...999" in unknown and "999voltage_v, unknown-00, " in unknown
    assert unknown.endswith(", unknown-06 and 23 more are not defined by devicetree.power.supply.battery "
                            "(additionalProperties: false)")  # fmt: skip
    # the pattern property's finding keeps the tail of its path: which row and column is wrong
    assert any(m.startswith("ocv-capacity-table-999") and "999[0][0]" in m for m in messages), messages
