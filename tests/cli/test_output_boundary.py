"""The output boundary: text from an input (log field and topic names, logged strings, file names) never
reaches a terminal or a CI log raw -- no control character, no line that starts a GitHub workflow command,
no CSV cell a spreadsheet runs. Each test crafts the hostile input the way an attacker would."""

from __future__ import annotations

import csv
import io
import json
import struct
from pathlib import Path

import pytest
from fleet_samples import jsonl

from codegen.cli.main import main
from codegen.text.escape import csv_cell, github_data, github_property, line, shown
from generated import _ulog
from generated.uorb import BatteryStatus, BatteryStatusV0

# a workflow command on its own line, a terminal reset, clear screen, bell and a C1 CSI
EVIL = "\n::error file=X,line=1::pwned\x1bc\x1b[2J\x07\x9b31m"


def _record(kind: str, body: bytes) -> bytes:
    return struct.pack("<HB", len(body), ord(kind)) + body


def evil_field_log(path: Path) -> Path:
    """A ULog whose battery_status format has a field named EVIL (the 'only in the log' warning names it)
    and one record whose remaining = 1.5 is a finding."""
    fmt = f"battery_status:uint64_t timestamp;float voltage_v;float remaining;uint8_t warning;float {EVIL};"
    out = _ulog.MAGIC + bytes((1,)) + struct.pack("<Q", 0) + _record("B", bytes(40)) + _record("F", fmt.encode())
    out += _record("A", struct.pack("<BH", 0, 0) + b"battery_status")
    out += _record("D", struct.pack("<H", 0) + struct.pack("<QffBf", 1000, 12.0, 1.5, 0, 0.0))
    path.write_bytes(out)
    return path


def assert_safe(text: str, *, commands: bool = False) -> None:
    """No control character but newline, and no line starting a workflow command (unless ``commands``:
    then every line is one battgen wrote, a single ``::error``/``::warning`` line)."""
    assert not {c for c in text if (ord(c) < 0x20 and c != "\n") or 0x7F <= ord(c) < 0xA0}, repr(text)
    for row in text.splitlines():
        if commands:
            assert row.startswith(("::error file=", "::warning file=")) and row.count("::") == 2, row
        else:
            assert not row.lstrip().startswith("::"), row


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


# -- the escaping itself --------------------------------------------------------------------------------


def test_shown_writes_every_control_character_as_an_escape() -> None:
    assert shown("a\x00b\x1b[2J\x7f\x85\x9b") == "a\\x00b\\x1b[2J\\x7f\\x85\\x9b"
    assert shown("tab\there\nnext\r") == "tab\\x09here\\x0anext\\x0d"
    assert shown("evil\u202ereversed\u2028") == "evil\\u202ereversed\\u2028"
    assert shown("Zürich 4.2 V, µs") == "Zürich 4.2 V, µs"  # printable text stays as it is


def test_line_cannot_start_a_workflow_command() -> None:
    assert line("::error file=x::y") == "\\x3a:error file=x::y"
    assert line("  ::warning::y") == "  \\x3a:warning::y"  # the runner trims leading blanks
    assert line("log.ulg: a ::error:: in the middle") == "log.ulg: a ::error:: in the middle"
    assert line("x ##[error]y") == "x #\\x23[error]y"  # the runner's legacy prefix, anywhere in a line


def test_github_escaping_is_the_runners() -> None:
    assert github_data("100%\r\n::error::x\x1b") == "100%25%0D%0A::error::x\\x1b"
    assert github_property("a:b,c%\n") == "a%3Ab%2Cc%25%0A"


def test_csv_cell_guards_formulas_as_owasp_describes() -> None:
    for start in ("=", "+", "-", "@", "\t", "\r"):
        assert csv_cell(f"{start}1+1").startswith("'")
    assert csv_cell('=HYPERLINK("x")') == '\'=HYPERLINK("x")'
    assert csv_cell("a.tlog") == "a.tlog"


# -- validate, every format --------------------------------------------------------------------------------


def test_validate_text_escapes_a_field_name_of_the_log(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = evil_field_log(tmp_path / "evil.ulg")
    code, out, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(log))
    assert code == 1
    assert_safe(out)
    assert_safe(err)
    assert "only in the log: \\x0a::error file=X,line=1::pwned\\x1bc\\x1b[2J\\x07\\x9b31m float" in err


def test_validate_github_keeps_log_text_inside_its_annotation(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder = tmp_path / "x\n::error file=Y,line=2::b"  # a folder name is as much input as the log
    folder.mkdir()
    log = evil_field_log(folder / "evil.ulg")
    code, out, err = run(capsys, "validate", "--format", "github", "--message", "uorb.BatteryStatus", str(log))
    assert code == 1
    assert_safe(out, commands=True)
    assert_safe(err)
    [annotation] = out.splitlines()
    assert annotation.startswith("::error file=") and "x%0A%3A%3Aerror file=Y%2Cline=2%3A%3Ab/evil.ulg" in annotation


def test_validate_github_notice_of_a_file_without_records(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = tmp_path / "a\r\n::warning::b\x1b]0;t\x07.ulg"
    _ulog.write(log, [BatteryStatusV0()])
    code, out, err = run(capsys, "validate", "--format", "github", "--message", "uorb.BatteryStatus", str(log))
    assert code == 1
    assert_safe(out, commands=True)
    assert_safe(err)
    assert "a%0D%0A%3A%3Awarning%3A%3Ab\\x1b]0;t\\x07.ulg" in out


def test_validate_sarif_reports_a_log_without_records(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = tmp_path / "v0.ulg"
    _ulog.write(log, [BatteryStatusV0()])
    for allow, level in ((False, "error"), (True, "note")):
        args = ["validate", "--format", "sarif", "--message", "uorb.BatteryStatus", str(log)]
        code, out, _ = run(capsys, *args, *(["--allow-empty"] if allow else []))
        [invocation] = json.loads(out)["runs"][0]["invocations"]
        notes = invocation["toolExecutionNotifications"]
        assert code == (0 if allow else 1)
        assert [n["level"] for n in notes] == ["warning", level]
        assert "topics logged: battery_status_v0" in notes[0]["message"]["text"]
        assert "no uorb.BatteryStatus records in this file" in notes[1]["message"]["text"]


# -- convert, failsafe, errors, can ---------------------------------------------------------------------------


def test_convert_stderr_escapes_the_log(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = evil_field_log(tmp_path / "evil.ulg")
    # px4: the record's remaining = 1.5 is validate's error, which --policy strict refuses
    code, out, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", "--policy", "px4", str(log))
    assert code == 0 and "\\x0a::error file=X" in err
    assert_safe(err)
    json.loads(out)  # JSON output escapes by its own rules


def test_failsafe_escapes_the_stream_name(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = tmp_path / "f\n::error::x\x1b[2J.ulg"
    _ulog.write(log, [BatteryStatus(timestamp=1000 * i, voltage_v=12.0, remaining=0.5) for i in range(3)])
    params = tmp_path / "p.param"
    params.write_text("BATT_MONITOR 4\nBATT_LOW_VOLT 10.5\n", encoding="utf-8")
    code, out, err = run(capsys, "failsafe", "--params", str(params), str(log))
    assert code == 0 and "f\\x0a::error::x\\x1b[2J.ulg" in err
    assert_safe(out)
    assert_safe(err)


def test_an_error_naming_a_hostile_file_is_one_escaped_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    log = tmp_path / "j\n::error::x\x07.ulg"
    log.write_bytes(b"not a log\n")
    code, out, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(log))
    assert code == 2 and out == ""
    assert_safe(err)
    assert "j\\x0a::error::x\\x07.ulg: expected a ULog file" in err


def test_can_escapes_the_capture_name(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    pytest.importorskip("can")
    capture = tmp_path / "c\n::error::x\x1b[2J.log"
    capture.write_text("(0.000000) can0 1E0C2A7F#C0\n(0.100000) can0 1E0C2A7F#C1\n", encoding="utf-8")
    code, out, err = run(capsys, "can", str(capture))
    assert "c\\x0a::error::x\\x1b[2J.log" in out + err
    assert_safe(out)
    assert_safe(err)
    assert code in (0, 1)


# -- query: table and CSV ---------------------------------------------------------------------------------


@pytest.fixture
def hostile_dataset(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    """A dataset of one ULog whose sys_uuid holds terminal escapes and a formula, and one JSON Lines file
    whose name is a formula."""
    pytest.importorskip("duckdb")
    logs = tmp_path / "logs"
    logs.mkdir()
    records = [BatteryStatus(timestamp=1_000_000 * (i + 1), voltage_v=12.0, remaining=0.5) for i in range(3)]
    _ulog.write(logs / "u.ulg", records, info={"sys_uuid": "=1+2\x1b[2J\x1b]0;pwn\x07"})
    jsonl(logs / "@SUM(A1).jsonl")
    out = tmp_path / "ds"
    assert main(["export", str(logs), "-o", str(out), "-q"]) == 0
    capsys.readouterr()
    return out


def test_query_table_escapes_logged_text(capsys: pytest.CaptureFixture[str], hostile_dataset: Path) -> None:
    code, out, _ = run(capsys, "query", str(hostile_dataset), "SELECT DISTINCT vehicle FROM battery ORDER BY 1")
    assert code == 0
    assert_safe(out)
    assert "=1+2\\x1b[2J\\x1b]0;pwn\\x07" in out


def test_query_csv_guards_formulas_unless_raw(capsys: pytest.CaptureFixture[str], hostile_dataset: Path) -> None:
    sql = "SELECT DISTINCT source, vehicle, -1.5 AS current FROM battery ORDER BY source"
    code, out, _ = run(capsys, "query", str(hostile_dataset), sql, "--format", "csv")
    assert code == 0
    assert_safe(out)
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[1][0] == "'@SUM(A1).jsonl" and rows[2][1] == "'=1+2\\x1b[2J\\x1b]0;pwn\\x07"
    assert rows[1][2] == "-1.5"  # a number is data, never guarded
    code, out, _ = run(capsys, "query", str(hostile_dataset), sql, "--format", "csv", "--csv-raw")
    rows = list(csv.reader(io.StringIO(out)))
    assert code == 0 and rows[1][0] == "@SUM(A1).jsonl" and rows[2][1] == "=1+2\x1b[2J\x1b]0;pwn\x07"


# -- files battgen writes that quote an input ------------------------------------------------------------------


def test_a_proposed_parameter_file_cannot_gain_a_line_from_the_board_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from test_failsafe_cli import DTS

    dts = tmp_path / "b\nBATT_LOW_VOLT,0\n.dts"  # the header quotes the source: a parameter line of its own
    dts.write_text(DTS, encoding="utf-8")
    out = tmp_path / "proposed.param"
    assert main(["params", "--from-devicetree", str(dts), "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert "BATT_LOW_VOLT,0\n" not in text and "b\\x0aBATT_LOW_VOLT,0\\x0a.dts" in text
    assert [ln for ln in text.splitlines() if ln.startswith("BATT_LOW_VOLT,")] == [
        next(ln for ln in text.splitlines() if ln.startswith("BATT_LOW_VOLT,11.25"))
    ]
    capsys.readouterr()
