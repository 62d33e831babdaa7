"""`battgen validate`: data files checked with the generated validators, one line per violation.

Exit codes: 0 valid, 1 violations, 2 unreadable input or unknown message; never a traceback.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tracemalloc
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml
from conftest import ROOT

from codegen.apps.gate.validate import Checker, exit_code, make_checker
from codegen.apps.schemas.messages import resolve_message
from codegen.cli.main import build_parser, main
from codegen.cli.validate import check_file
from codegen.frontends.loader import load
from codegen.inputs.dispatch import read_records
from codegen.inputs.records import Record
from codegen.ir import Location, Message, SourceFormat

DATA = ROOT / "tests" / "data" / "instances"
SCHEMAS = ROOT / "schemas"


def validate(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[str], str]:
    code = main(["validate", *args])
    captured = capsys.readouterr()
    return code, [line for line in captured.out.splitlines() if line], captured.err


# -- results and exit codes ------------------------------------------------------------------------


def test_valid_json_with_nan_tokens_and_strings_passes(capsys: pytest.CaptureFixture[str]) -> None:
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", str(DATA / "uorb_valid.json"))
    assert (code, lines) == (0, [])
    assert "2 records in 1 file, 0 errors" in err


def test_invalid_json_names_file_line_and_field(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "uorb_invalid.json"
    code, lines, _ = validate(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 1
    by_line = {int(line.split(":")[1]): line for line in lines}
    assert set(by_line) == {5, 6, 7, 11}, lines  # the line of each offending value, not of its record
    assert all(line.startswith(f"{path.as_posix()}:") for line in lines)
    assert "remaining" in by_line[5] and "1.5" in by_line[5]
    assert "warning" in by_line[6] and "5" in by_line[6]
    assert "faults" in by_line[7]
    assert "voltage_v" in by_line[11] and "expected a number" in by_line[11]


def test_yaml_stream_of_documents_and_lists(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "uorb_stream.yaml"
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 1
    assert "3 records" in err
    assert len(lines) == 1 and lines[0].startswith(f"{path.as_posix()}:14: ") and "remaining" in lines[0]


def test_json_lines_report_line_numbers_and_malformed_lines(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "uorb_records.jsonl"
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 2  # line 5 is not JSON: unreadable input wins over violations
    assert len(lines) == 1 and lines[0].startswith(f"{path.as_posix()}:4: ") and "remaining" in lines[0]
    assert f"{path.as_posix()}:5: expected one JSON value per line" in err


def test_json_format_is_machine_readable(capsys: pytest.CaptureFixture[str]) -> None:
    files = [str(DATA / "uorb_invalid.json"), str(DATA / "uorb_valid.json")]
    code, lines, _ = validate(capsys, "--message", "uorb.BatteryStatus", "--format", "json", *files)
    assert code == 1
    doc = json.loads("\n".join(lines))
    assert doc["message"] == "uorb.BatteryStatus" and doc["valid"] is False
    invalid, valid = doc["files"]
    assert (invalid["records"], valid["records"]) == (3, 2)
    assert valid["violations"] == [] and valid["errors"] == 0
    for v in invalid["violations"]:
        assert set(v) >= {"path", "rule", "value", "limit", "message", "severity", "line"}
    type_errors = [v for v in invalid["violations"] if v["rule"] == "type"]
    assert [(v["path"], v["line"], v["value"]) for v in type_errors] == [("voltage_v", 11, "sixteen")]
    remaining = next(v for v in invalid["violations"] if v["path"] == "remaining")
    assert (remaining["rule"], remaining["value"], remaining["line"], remaining["severity"]) == (
        "range",
        1.5,
        5,
        "error",
    )


def test_json_format_writes_non_finite_values_as_strings(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    data = tmp_path / "nan.json"
    data.write_text('{"voltage_v": NaN, "remaining": Infinity}')
    code, lines, _ = validate(capsys, "--message", "uorb.BatteryStatus", "--format", "json", str(data))
    doc = json.loads("\n".join(lines))  # strict JSON: would fail on a bare NaN
    values = {v["path"]: v["value"] for v in doc["files"][0]["violations"]}
    assert code == 1
    assert values.get("remaining") == "Infinity"


def test_malformed_json_is_one_line_and_exit_2_without_traceback() -> None:
    path = DATA / "malformed.json"
    proc = subprocess.run(
        [sys.executable, "-m", "codegen", "validate", "--message", "uorb.BatteryStatus", str(path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert f"{path.as_posix()}:3: malformed JSON" in proc.stderr


@pytest.mark.parametrize(
    ("content", "suffix", "line", "expected"),
    [
        ("", ".json", 1, "malformed JSON: Expecting value"),
        ('[{"a": 1} {"b": 2}]', ".json", 1, "expected ',' or ']'"),
        ('{"a": 1}\n{"b": 2}\n', ".json", 2, "expected the end of the file"),
        ("a: [1, 2\nb: 3\n", ".yaml", 2, "malformed YAML"),
        ("a: 1\n\tb: 2\n", ".yml", 2, "malformed YAML"),
    ],
)
def test_unreadable_input_names_file_and_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, content: str, suffix: str, line: int, expected: str
) -> None:
    path = tmp_path / f"bad{suffix}"
    path.write_text(content)
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert (code, lines) == (2, [])
    assert f"{path.as_posix()}:{line}: " in err and expected in err


def test_missing_file_and_unknown_extension_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = validate(capsys, "--message", "uorb.BatteryStatus", str(tmp_path / "absent.json"))
    assert code == 2 and "absent.json: cannot read file" in err
    other = tmp_path / "data.csv"
    other.write_text("voltage_v\n1\n")
    code, _, err = validate(capsys, "--message", "uorb.BatteryStatus", str(other))
    assert code == 2 and "data.csv" in err and "expected one of" in err and ".jsonl" in err


def test_non_object_records_and_unknown_fields_are_type_violations(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "odd.json"
    path.write_text('[\n  [1, 2],\n  {"volts": 3}\n]\n')
    code, lines, _ = validate(capsys, "--message", "uorb.BatteryStatus", str(path))
    assert code == 1
    assert lines[0].startswith(f"{path.as_posix()}:2: ") and "expected an object" in lines[0]
    assert lines[1] == f"{path.as_posix()}:3: volts is not a field of uorb.BatteryStatus"


def test_empty_inputs_are_not_success(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    (tmp_path / "a.json").write_text("[]")
    (tmp_path / "b.jsonl").write_text("\n\n")
    (tmp_path / "c.yaml").write_text("# nothing\n")
    files = [str(tmp_path / n) for n in ("a.json", "b.jsonl", "c.yaml")]
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", *files)
    assert (code, lines) == (1, [])
    for f in files:
        assert f"{Path(f).as_posix()}: no uorb.BatteryStatus records in this file (--allow-empty accepts that)" in err
    assert "0 records in 3 files, 0 errors, 0 warnings, 3 without records" in err
    code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", "--allow-empty", *files)
    assert (code, lines) == (0, []) and "no uorb" not in err


# -- message names ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "qualified"),
    [
        ("uorb.BatteryStatus", "uorb.BatteryStatus"),
        ("BatteryStatusV0", "uorb.BatteryStatusV0"),
        ("mavlink.BATTERY_STATUS", "mavlink.BATTERY_STATUS"),
        ("BATTERY_STATUS", "mavlink.BATTERY_STATUS"),
        ("BATTERY_INFO", "mavlink.BATTERY_INFO"),
        ("BatteryStatusV2", "mavlink.BATTERY_STATUS_V2"),
        ("power.BatteryInfo", "dronecan.uavcan.equipment.power.BatteryInfo"),
        ("uorb.BatteryInfo", "uorb.BatteryInfo"),
        ("uavcan.equipment.power.BatteryInfo", "dronecan.uavcan.equipment.power.BatteryInfo"),
        ("devicetree.power.supply.battery", "devicetree.power.supply.battery"),
        ("simple-battery", "devicetree.power.supply.battery"),
    ],
)
def test_message_names_resolve(name: str, qualified: str) -> None:
    assert resolve_message(load([SCHEMAS]), name).qualified_name == qualified


def test_ambiguous_and_unknown_message_names_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = validate(capsys, "--message", "BatteryStatus", str(DATA / "uorb_valid.json"))
    assert code == 2
    assert "ambiguous" in err and "mavlink.BATTERY_STATUS" in err and "uorb.BatteryStatus" in err
    code, _, err = validate(capsys, "--message", "BatteryInfo", str(DATA / "uorb_valid.json"))
    assert code == 2 and "uorb.BatteryInfo" in err and "dronecan.uavcan.equipment.power.BatteryInfo" in err
    code, _, err = validate(capsys, "--message", "BatteryStatu", str(DATA / "uorb_valid.json"))
    assert code == 2 and "no message called 'BatteryStatu'" in err and "did you mean 'BatteryStatus'" in err


def test_devicetree_files_need_a_devicetree_message(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    dts = tmp_path / "board.dts"
    dts.write_text("/dts-v1/;\n/ { };\n")
    code, _, err = validate(capsys, "--message", "uorb.BatteryStatus", str(dts))
    assert code == 2 and "uorb.BatteryStatus is a uorb message" in err


# -- devicetree ----------------------------------------------------------------------------------


def test_dts_nodes_are_checked_with_node_paths_and_property_lines(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "battery_board.dts"
    code, lines, err = validate(capsys, "--message", "simple-battery", str(path))
    assert code == 1
    assert "2 records" in err  # the charger is not a simple-battery node
    # dt-validate's order: the binding's own checks first, battgen's cross-field rules after them
    assert lines[0].startswith(f"{path.as_posix()}:23: /battery-spare: ocv-capacity-table-0[0][1]")
    assert lines[1].startswith(f"{path.as_posix()}:20: /battery-spare: voltage-min-design-microvolt = 4200000 uV")
    assert "120" in lines[0] and len(lines) == 2


def test_advice_rules_warn_without_failing(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "battery_advice.dts"
    code, lines, err = validate(capsys, "--message", "devicetree.power.supply.battery", str(path))
    assert code == 0
    assert lines == [
        f"{path.as_posix()}:8: warning: /battery: voltage-max-design-microvolt = 4200000 uV is below "
        "constant-charge-voltage-max-microvolt = 4350000 uV"
    ]
    assert "0 errors, 1 warning" in err


@pytest.mark.skipif(shutil.which("dtc") is None, reason="needs dtc (Debian device-tree-compiler)")
def test_dtb_gives_the_same_verdict_as_its_source(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    source = DATA / "battery_board.dts"
    blob = tmp_path / "board.dtb"
    subprocess.run(["dtc", "-q", "-I", "dts", "-O", "dtb", "-o", str(blob), str(source)], check=True)
    results = {}
    for path in (source, blob):
        code, lines, _ = validate(capsys, "--message", "simple-battery", "--format", "json", str(path))
        violations = json.loads("\n".join(lines))["files"][0]["violations"]
        results[path.suffix] = (code, [(v["node"], v["path"], v["rule"], v["message"]) for v in violations])
        lines_seen = {v["line"] for v in violations}
        assert lines_seen == ({None} if path == blob else {20, 23})
    # the same violations; a .dts lists them by line, a blob (no lines) in validate()'s order
    assert (results[".dts"][0], sorted(results[".dts"][1])) == (results[".dtb"][0], sorted(results[".dtb"][1]))
    assert results[".dtb"][0] == 1 and len(results[".dtb"][1]) == 2
    code, lines, _ = validate(capsys, "--message", "simple-battery", str(blob))
    assert lines[0].startswith(f"{blob.as_posix()}: /battery-spare: ")  # a blob has no line numbers


@pytest.mark.parametrize(
    ("name", "content", "expected"),
    [
        ("bad.dts", '/dts-v1/;\n/ {\n  battery { compatible = "simple-battery"\n };\n', ":4: expected ';'"),
        ("bad.dtb", "not a blob", "bad.dtb: byte 0x0"),
    ],
)
def test_unreadable_devicetree_input_exits_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str, content: str, expected: str
) -> None:
    path = tmp_path / name
    path.write_text(content)
    code, lines, err = validate(capsys, "--message", "simple-battery", str(path))
    assert (code, lines) == (2, [])
    assert expected in err and "Traceback" not in err


# -- other schema folders --------------------------------------------------------------------------


def test_other_schema_folder_is_generated_and_imported(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    schemas = tmp_path / "myschemas"
    (schemas / "uorb").mkdir(parents=True)
    (schemas / "uorb" / "Gauge.msg").write_text("uint64 timestamp # [us] time\nuint8 level # [@range 0, 10] level\n")
    data = tmp_path / "gauge.jsonl"
    data.write_text('{"level": 3}\n{"level": 11}\n{"level": "high"}\n')
    code, lines, _ = validate(capsys, "--schemas", str(schemas), "--message", "Gauge", str(data))
    assert code == 1
    assert any(line.startswith(f"{data.as_posix()}:2: ") and "level" in line for line in lines)
    assert any(line.startswith(f"{data.as_posix()}:3: ") and "expected an integer" in line for line in lines)
    # the package is generated once per process and per schema folder
    first = make_checker(schemas, "Gauge")[1].cls
    assert make_checker(schemas, "uorb.Gauge")[1].cls is first
    assert first.__module__.startswith("_battgen_models_")


def test_bundled_schemas_use_the_committed_package() -> None:
    import generated.uorb

    _, checker = make_checker(SCHEMAS, "uorb.BatteryStatus")
    assert checker.cls is generated.uorb.BatteryStatus


# -- warnings and exit codes, with a stand-in model ------------------------------------------------


class _DataError(ValueError):
    def __init__(self, path: str, expected: str, value: object) -> None:
        super().__init__(path)
        self.path, self.expected, self.value = path, expected, value


class _Model:
    @classmethod
    def from_dict(cls, data: Any) -> _Model:
        if not isinstance(data, dict):
            raise _DataError("_Model", "an object", data)
        obj = cls()
        obj.data = data
        return obj

    data: dict[str, Any]

    def validate(self) -> list[SimpleNamespace]:
        return [
            SimpleNamespace(path=k, rule="cross-field:advice", value=v, limit=0, message=f"{k} is odd", severity=s)
            for k, (v, s) in self.data.items()
        ]


_MSG = Message("M", "test.M", SourceFormat.UORB, Location("m.msg", 1), "", ())


def test_warnings_are_printed_but_do_not_fail(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "w.jsonl"
    path.write_text('{"a": [1, "warning"]}\n')
    report = check_file(path, _MSG, Checker(_Model, _MSG, _DataError), echo=True)
    assert capsys.readouterr().out == f"{path.as_posix()}:1: warning: a is odd\n"
    assert (report.warnings, report.errors, exit_code([report])) == (1, 0, 0)
    path.write_text('{"a": [1, "warning"]}\n{"b": [2, "error"]}\n')
    report = check_file(path, _MSG, Checker(_Model, _MSG, _DataError), echo=True)
    assert capsys.readouterr().out.splitlines()[1] == f"{path.as_posix()}:2: b is odd"
    assert (report.warnings, report.errors, exit_code([report])) == (1, 1, 1)


def test_a_failing_model_never_raises(tmp_path: Path) -> None:
    class Broken(_Model):
        def validate(self) -> list[SimpleNamespace]:
            raise RuntimeError("boom")

    record = Record(0, 7, {"a": 1}, "f.json")
    (finding,) = Checker(Broken, _MSG, _DataError).check(record)
    assert (finding.line, finding.rule, finding.severity) == (7, "internal", "error") and "boom" in finding.message


# -- record locations ------------------------------------------------------------------------------


def test_json_field_lines_are_found_inside_records(tmp_path: Path) -> None:
    path = tmp_path / "r.json"
    path.write_text('[{"a": 1},\n {\n  "b": {"c": 2,\n   "d": [1,\n    2]},\n  "e": "x"\n }\n]\n')
    records = [r for r in read_records(path, _MSG) if isinstance(r, Record)]
    assert [r.line for r in records] == [1, 2]
    second = records[1]
    assert [second.line_of(p) for p in ("b", "b.c", "b.d", "b.d[1]", "b.d[7]", "e", "zz")] == [3, 3, 4, 5, 4, 6, 2]


def test_yaml_field_lines_are_found_inside_records(tmp_path: Path) -> None:
    path = tmp_path / "r.yaml"
    path.write_text("a: 1\nb:\n  c: 2\n  d:\n    - 1\n    - 2\n---\n- x: 1\n- y: [1,\n     2]\n")
    records = [r for r in read_records(path, _MSG) if isinstance(r, Record)]
    assert [(r.index, r.line) for r in records] == [(0, 1), (1, 8), (2, 9)]
    assert [records[0].line_of(p) for p in ("a", "b.c", "b.d[1]", "q")] == [1, 3, 6, 1]
    assert records[2].line_of("y[1]") == 10


# -- JSON Lines streaming --------------------------------------------------------------------------


def _peak_memory(path: Path, checker: Checker, message: Message) -> int:
    tracemalloc.start()
    try:
        report = check_file(path, message, checker, echo=True)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert report.records > 0 and not report.unreadable
    assert report.errors == 0  # printed violations would pile up in the captured output
    return peak


def test_json_lines_stream_in_constant_memory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    message, checker = make_checker(SCHEMAS, "uorb.BatteryStatus")
    line = '{"voltage_v": 16.4, "remaining": 0.5, "cell_count": 4, "temperature": NaN, "max_error": 1}\n'
    small, large = tmp_path / "small.jsonl", tmp_path / "large.jsonl"
    small.write_text(line * 1_000)
    large.write_text(line * 12_000)  # about 1.1 MB, read under tracemalloc in a few seconds
    peak_small = _peak_memory(small, checker, message)
    peak_large = _peak_memory(large, checker, message)
    capsys.readouterr()
    assert large.stat().st_size > 1_000_000
    # measured: about 31 kB for both: nothing accumulates per record
    assert peak_large < 256 * 1024, peak_large
    assert peak_large < peak_small + 16 * 1024, (peak_small, peak_large)


# -- pre-commit hooks ------------------------------------------------------------------------------


def test_pre_commit_hooks_parse_and_name_existing_commands() -> None:
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text(encoding="utf-8"))
    by_id = {h["id"]: h for h in hooks}
    assert set(by_id) == {"battgen-validate", "battgen-generate-check"}
    for hook in hooks:
        assert {"id", "name", "entry", "language"} <= set(hook)
        assert hook["language"] == "python"
        program, *argv = hook["entry"].split()
        assert program == "battgen"
        # the entry, with what a user would add, is accepted by the real parser
        extra = ["--message", "uorb.BatteryStatus", "x.json"] if hook["id"] == "battgen-validate" else []
        args = build_parser().parse_args([*argv, *extra])
        assert callable(args.func)
    assert by_id["battgen-generate-check"]["pass_filenames"] is False
    assert by_id["battgen-generate-check"]["entry"] == "battgen generate --check"
    assert by_id["battgen-validate"].get("pass_filenames", True) is True
    import re

    pattern = re.compile(by_id["battgen-validate"]["files"])
    for name in ("a.json", "b.jsonl", "c.ndjson", "d.yaml", "e.yml", "board.dts", "board.dtb"):
        assert pattern.search(name), name
    assert not pattern.search("README.md")


# -- battgen schema --------------------------------------------------------------------------------


def test_schema_command_prints_a_draft_2020_12_schema(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    import jsonschema

    assert main(["schema", "--message", "uorb.BatteryStatus"]) == 0
    doc = json.loads(capsys.readouterr().out)
    jsonschema.Draft202012Validator.check_schema(doc)
    validator = jsonschema.Draft202012Validator(doc)
    assert validator.is_valid({"voltage_v": 16.4, "remaining": -1, "temperature": "NaN", "max_error": 1})
    assert not validator.is_valid({"voltage_v": 16.4, "remaining": 1.5, "max_error": 1})
    assert main(["schema", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "mavlink.BATTERY_STATUS.schema.json").is_file()
    assert main(["schema", "--message", "BatteryStatus"]) == 2  # ambiguous
    capsys.readouterr()


def test_hostile_inputs_end_in_one_line_each(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    deep = "[" * 100_000 + "]" * 100_000
    for name in ("deep.json", "deep.jsonl"):
        (tmp_path / name).write_text(deep + "\n")
        code, lines, err = validate(capsys, "--message", "uorb.BatteryStatus", str(tmp_path / name))
        assert (code, lines) == (2, []) and f"{name}:1: values nested too deeply to read" in err
    # an alias bomb: line lookups walk each anchored node once, not 9**9 times
    levels = ["l0: &l0 [1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    levels += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, 9)]
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("\n".join(levels) + "\n")
    code, lines, _ = validate(capsys, "--message", "uorb.BatteryStatus", str(bomb))
    assert code == 1 and lines == [f"{bomb.as_posix()}:1: l0 is not a field of uorb.BatteryStatus"]
