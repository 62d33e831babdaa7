"""A gate that cannot be fooled: a misspelt rule or field in ``--select``/``--ignore``/``[tool.battgen]``, an
unknown profile or vehicle, fails ``validate`` and ``report`` with exit 2 and the closest names; and a PX4 log is
judged by what PX4 writes (the px4 profile, chosen from the log's firmware unless given)."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest
from shared_data import REAL_LOGS, missing, real_logs

from codegen.apps.gate.selection import GENERIC_RULES, load_profile, names_of, profile_names, unknown_selector
from codegen.apps.gate.validate import make_checker
from codegen.apps.schemas.package import bundled_schemas
from codegen.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
EVENTS = REAL_LOGS / "sample_px4_events.ulg"


def _events() -> str:
    if not EVENTS.is_file():
        missing("the shared real PX4 logs")
    return str(EVENTS)


def test_generic_rules_are_the_generated_validators() -> None:
    """GENERIC_RULES is every rule a generated Violation carries (read off generated/_validate.py), plus the
    validate app's "internal"."""
    tree = ast.parse((ROOT / "generated" / "_validate.py").read_text())
    found = {
        node.args[1].value
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and getattr(node.func, "id", None) == "Violation"
        and isinstance(node.args[1], ast.Constant)
    }
    assert set(GENERIC_RULES) == found | {"internal"}


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ("--select", "rnage"),
            "--select: no rule or field of uorb.BatteryStatus is called 'rnage' (did you mean range?)",
        ),
        (
            ("--ignore", "range/max_eror"),
            "--ignore: uorb.BatteryStatus has no field 'max_eror' (did you mean max_error?)",
        ),
        (
            ("--ignore", "rnge/max_error"),
            "--ignore: no rule of uorb.BatteryStatus is called 'rnge' (did you mean range?)",
        ),
        (("--select", "zz*"), "--select: no rule or field of uorb.BatteryStatus is called 'zz*'"),
        (("--profile", "px5"), "--profile: unknown profile 'px5' (did you mean px4?) (bundled profiles: px4)"),
    ],
)
@pytest.mark.parametrize("command", ["validate", "report"])
def test_a_misspelt_name_is_exit_2_with_the_closest(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, command: str, argv: tuple[str, ...], expected: str
) -> None:
    extra = ["-o", str(tmp_path / "r.html")] if command == "report" else []
    code = main([command, *argv, *extra, _events()])
    err = capsys.readouterr().err
    assert code == 2 and err.splitlines()[-1] == f"battgen: {expected}"
    assert not (tmp_path / "r.html").exists()


@pytest.mark.parametrize("command", ["validate", "report"])
def test_a_misspelt_name_in_pyproject_is_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: str
) -> None:
    (tmp_path / "pyproject.toml").write_text('[tool.battgen]\nselect = ["max_error", "cells-beyond-count-zeor"]\n')
    monkeypatch.chdir(tmp_path)
    extra = ["-o", str(tmp_path / "r.html")] if command == "report" else []
    code = main([command, *extra, _events()])
    err = capsys.readouterr().err.splitlines()[-1]
    assert code == 2
    assert err == (
        f"battgen: {tmp_path.as_posix()}/pyproject.toml: [tool.battgen] select: no rule or field of "
        "uorb.BatteryStatus is called 'cells-beyond-count-zeor' (did you mean cells-beyond-count-zero, "
        "cross-field:cells-beyond-count-zero?)"
    )


def test_report_refuses_an_unknown_vehicle(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code = main(["report", "--vehicle", "coptr", "-o", str(tmp_path / "r.html"), _events()])
    assert code == 2 and "unknown vehicle 'coptr' (did you mean copter?)" in capsys.readouterr().err


def test_good_names_pass_and_wildcards_must_match_something() -> None:
    message, checker = make_checker(bundled_schemas(), "uorb.BatteryStatus")
    names = names_of(message, checker.rules)
    for good in ("range", "range/max_error", "max_error", "r?nge/*", "cells-beyond-count-zero", "cross-field:*"):
        assert unknown_selector(good, names) is None, good
    assert unknown_selector("voltage_cell_v[3]", names) is not None  # fields are named without indexes
    params, checker = make_checker(bundled_schemas(), "params.BATT")
    assert (
        unknown_selector("failsafe/BATT_LOW_VOLT", names_of(params, checker.rules, checker.extra is not None)) is None
    )


def test_every_waiver_of_every_profile_names_something_of_its_message() -> None:
    for name in profile_names():
        for waiver in load_profile(name).waivers:
            message, checker = make_checker(bundled_schemas(), waiver.message)
            assert unknown_selector(waiver.selector, names_of(message, checker.rules)) is None, waiver


PX4_LOGS = real_logs()


@pytest.mark.parametrize("log", PX4_LOGS, ids=[p.name for p in PX4_LOGS])
def test_a_px4_logs_default_report_and_validation_have_no_finding_px4_explains(
    capsys: pytest.CaptureFixture[str], log: Path
) -> None:
    """No profile given: the log's firmware (PX4) chooses px4, said on stderr; ``--profile ''`` brings the
    max_error findings back, as PX4's battery library writes them."""
    code = main(["validate", str(log)])
    err = capsys.readouterr().err
    assert code == 0 and f"{log.as_posix()}: note: profile px4, as the log's firmware is px4" in err
    assert main(["report", "--format", "json", str(log)]) == 0
    out, err = capsys.readouterr()
    (item,) = json.loads(out)["inputs"]
    assert (
        item["findings"] == 0
        and "note: profile px4, as the log's firmware is PX4 v1." in err
        and "--profile '' for none" in err
    )
    assert main(["report", "--format", "json", "--profile", "", str(log)]) == 0
    (item,) = json.loads(capsys.readouterr().out)["inputs"]
    assert item["findings"] == item["records"]  # every record's max_error = 0


def test_one_did_you_mean_for_every_command() -> None:
    """The gate's hints and the other commands' come from one matcher (codegen.errors.close_names): case is ignored
    and a dotted name's last part is compared, wherever the name was typed; each keeps its own sentence."""
    from codegen.apps.gate.selection import closest, unknown_name
    from codegen.errors import close_names, did_you_mean

    known = ["copter", "plane", "rover", "uorb.BatteryStatus"]
    assert close_names("COPTR", known) == ["copter"] and close_names("px4.BatteryStatu", known) == [
        "uorb.BatteryStatus"
    ]
    assert closest("COPTR", known) == " (did you mean copter?)"
    assert did_you_mean("COPTR", known) == "did you mean 'copter'?"
    assert str(unknown_name("vehicle", "px4.BatteryStatu", known)) == (
        "unknown vehicle 'px4.BatteryStatu' (did you mean uorb.BatteryStatus?)"
    )
    assert str(unknown_name("vehicle", "boat", known)) == (
        "unknown vehicle 'boat' (known: copter, plane, rover, uorb.BatteryStatus)"
    )
