"""``battgen validate`` as a CI gate: rule selection (--select/--ignore, [tool.battgen] in
pyproject.toml), the bundled px4 profile of known firmware deviations, grouped findings, and the
github and sarif formats (SARIF checked against its published JSON Schema, stored in tests/data)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
from shared_data import REAL_LOGS, missing

from codegen.apps.gate.selection import finding_code, load_profile, matches, profile_names
from codegen.cli.main import main
from codegen.frontends.loader import load

ROOT = Path(__file__).resolve().parents[2]
SARIF_SCHEMA = json.loads((ROOT / "tests" / "data" / "sarif" / "sarif-schema-2.1.0.json").read_text())
LOGS = ("sample_log_small.ulg", "sample_px4_events.ulg")
GOOD = '{"voltage_v": 12.0, "remaining": 0.5, "max_error": 1}'


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, list[str], str]:
    code = main(["validate", *argv])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err


def logs() -> list[str]:
    paths = [REAL_LOGS / n for n in LOGS]
    if not all(p.is_file() for p in paths):
        missing("the shared real PX4 logs")
    return [str(p) for p in paths]


def test_real_logs_are_green_under_the_px4_profile(capsys: pytest.CaptureFixture[str]) -> None:
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", "--profile", "px4", *logs())
    assert (code, lines) == (0, [])
    summary = err.splitlines()[-1]
    assert summary.startswith("uorb.BatteryStatus: 199 records in 2 files, 0 errors, 0 warnings; 199 findings left out")
    assert "profile px4: range/max_error" in summary and summary.endswith("[profile px4]")


def test_without_the_profile_max_error_is_reported_once_per_log_grouped(capsys: pytest.CaptureFixture[str]) -> None:
    small, events = logs()
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", "--profile", "", small, events)
    assert code == 1 and len(lines) == 2
    assert lines[0] == (
        f"{small}: battery_status multi_id 0, timestamp 20630667 us, offset 86347: max_error = 0 % is below the "
        "minimum 1 % (and 41 more records like it, the last: battery_status multi_id 1, timestamp 26630309 us, "
        "offset 895765)"
    )
    assert lines[1].startswith(f"{events}: battery_status multi_id 0, ") and "(and 156 more records like it" in lines[1]
    assert "199 records in 2 files, 199 errors, 0 warnings (shown as 2 lines)" in err


@pytest.mark.parametrize(
    ("selector", "hit"),
    [
        ("range/max_error", True),
        ("range", True),
        ("max_error", True),
        ("range/*", True),
        ("r?nge/max_*", True),
        ("nan", False),
        ("range/cell_count", False),
        ("cells-beyond-count-zero", False),
    ],
)
def test_selectors_match_rule_field_or_both(selector: str, hit: bool) -> None:
    assert matches(selector, "range", "max_error") is hit


def test_selectors_on_arrays_and_cross_field_rules() -> None:
    rule = "cross-field:cells-beyond-count-zero"
    assert finding_code(rule, "voltage_cell_v[5]") == "cross-field:cells-beyond-count-zero/voltage_cell_v"
    for selector in ("cells-beyond-count-zero", rule, "voltage_cell_v", "cells-*/voltage_cell_v", "cross-field:*"):
        assert matches(selector, rule, "voltage_cell_v[5]"), selector
    assert not matches("voltage_cell_v[5]", rule, "voltage_cell_v[5]")  # fields are named without indexes


def test_select_and_ignore_on_the_command_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    path.write_text(GOOD + "\n" + '{"remaining": 7, "max_error": 0}\n')
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 1 and [line.split(": ", 1)[1] for line in lines] == [
        "remaining = 7 is above the maximum 1",
        "max_error = 0 % is below the minimum 1 %",
    ]
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", "--select", "remaining", str(path))
    assert code == 1 and len(lines) == 1 and "remaining" in lines[0]
    assert "1 finding left out: not selected" in err and "[select remaining]" in err
    code, lines, err = run(
        capsys, "--message", "uorb.BatteryStatus", "--ignore", "range/remaining,max_error", str(path)
    )
    assert (code, lines) == (0, []) and "2 findings left out: ignored (max_error); ignored (range/remaining)" in err


def test_pyproject_settings_from_the_working_folder_upward(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    data = tmp_path / "t.jsonl"
    data.write_text('{"voltage_v": 12.0, "max_error": 0}\n')
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n\n[tool.battgen]\nprofile = "px4"\n')
    (tmp_path / "deep" / "er").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "deep" / "er")
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", str(data))
    assert (code, lines) == (0, []) and f"[profile px4 from {tmp_path.as_posix()}/pyproject.toml]" in err
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", "--profile", "", str(data))
    assert code == 1 and len(lines) == 1  # the command line replaces the file's setting
    (tmp_path / "pyproject.toml").write_text("[tool.battgen]\nignores = []\n")
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", str(data))
    assert code == 2 and "[tool.battgen]: unknown key 'ignores' (expected select, ignore, profile)" in err
    (tmp_path / "pyproject.toml").write_text('[tool.battgen]\nignore = "max_error"\n')
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", str(data))
    assert code == 2 and "[tool.battgen] ignore: expected a list of selectors" in err
    code, lines, err = run(capsys, "--message", "uorb.BatteryStatus", "--ignore", "x", "--profile", "ardu", str(data))
    assert code == 2 and "unknown profile 'ardu' (bundled profiles: px4)" in err


def test_each_waiver_of_the_px4_profile_is_documented_and_needed(capsys: pytest.CaptureFixture[str]) -> None:
    """Every waiver names a message of the bundled schemas, a reason and evidence (upstream source
    and real logs); the uorb.BatteryStatus one is what the real logs need, and nothing more."""
    names = {m.qualified_name for m in load([ROOT / "schemas"]).messages}
    assert profile_names() == ["px4"]
    profile = load_profile("px4")
    for w in profile.waivers:
        assert w.message in names and w.reason and len(w.evidence) >= 1
        assert any("PX4" in e or "schemas/" in e for e in w.evidence)
    code = main(["validate", "--message", "uorb.BatteryStatus", "--format", "json", "--profile", "", *logs()])
    doc = json.loads(capsys.readouterr().out)
    assert code == 1
    codes = {finding_code(v["rule"], v["path"]) for f in doc["files"] for v in f["violations"]}
    assert codes == {w.selector for w in profile.waivers if w.message == "uorb.BatteryStatus"}


def test_github_annotations(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "a,b.jsonl"
    path.write_text(GOOD + "\n" + '{"remaining": 7}\n' * 3 + '{"temperature": "hot"}\n')
    code, lines, _ = run(capsys, "--message", "uorb.BatteryStatus", "--format", "github", str(path))
    f = path.as_posix().replace(",", "%2C")
    assert code == 1
    assert lines[0] == (
        f"::error file={f},line=2,title=battgen range/remaining::remaining = 7 is above the maximum 1 "
        "(and 2 more records like it, the last: line 4)"
    )
    assert lines[1] == (  # '%' escaped as GitHub's workflow commands require
        f"::error file={f},line=2,title=battgen range/max_error::max_error = 0 %25 is below the minimum 1 %25 "
        "(and 2 more records like it, the last: line 4)"
    )
    assert lines[2].startswith(f"::error file={f},line=5,title=battgen type/temperature::temperature: expected")
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    code, lines, _ = run(capsys, "--message", "uorb.BatteryStatus", "--format", "github", str(empty))
    assert code == 1 and lines == [
        f"::error file={empty.as_posix()},title=battgen::no uorb.BatteryStatus records in this file "
        "(--allow-empty accepts that)"
    ]


def _sarif(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict[str, object]]:
    code = main(["validate", "--format", "sarif", *argv])
    doc = json.loads(capsys.readouterr().out)
    jsonschema.Draft4Validator(SARIF_SCHEMA).validate(doc)
    return code, doc


def test_sarif_validates_against_the_published_schema(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    path.write_text(GOOD + "\n" + '{"remaining": 7, "max_error": 0}\n' * 2)
    code, doc = _sarif(capsys, "--message", "uorb.BatteryStatus", "--profile", "px4", str(path))
    (run_,) = doc["runs"]  # type: ignore[index]
    assert code == 1 and doc["version"] == "2.1.0"
    results = run_["results"]
    assert [(r["ruleId"], r["level"], r["properties"]["count"]) for r in results] == [
        ("range/remaining", "error", 2),
        ("range/max_error", "error", 2),
    ]
    assert results[0]["locations"][0]["physicalLocation"]["region"] == {"startLine": 2}
    assert "suppressions" not in results[0]
    (suppressed,) = results[1]["suppressions"]
    assert suppressed["kind"] == "external" and "never sets the field" in suppressed["justification"]
    assert [r["id"] for r in run_["tool"]["driver"]["rules"]] == ["range/remaining", "range/max_error"]
    assert run_["invocations"] == [{"executionSuccessful": True, "exitCode": 1}]


def test_sarif_of_real_logs_and_of_unreadable_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, doc = _sarif(capsys, "--message", "uorb.BatteryStatus", "--profile", "", *logs())
    results = doc["runs"][0]["results"]  # type: ignore[index]
    assert code == 1 and [r["properties"]["count"] for r in results] == [42, 157]
    assert results[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"].startswith("file:///")
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    code, doc = _sarif(capsys, "--message", "uorb.BatteryStatus", str(bad))
    (invocation,) = doc["runs"][0]["invocations"]  # type: ignore[index]
    assert code == 2 and invocation["executionSuccessful"] is False
    assert invocation["toolExecutionNotifications"][0]["message"]["text"].startswith(f"{bad.as_posix()}:1:")
