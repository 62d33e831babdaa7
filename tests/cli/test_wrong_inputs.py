"""What a new user meets on wrong input, every command: one line that names the file (and line, never a fake
line 0) and what was expected, a short "did you mean" for a misspelt name, and the exit code the README states
(2 unreadable input or bad usage, 1 a readable input without what the command needs, 0 with --allow-empty).

One table row per case of issue 28's list; each row writes its own input files (its fixture) into a fresh folder,
runs the command in-process and checks the exit code, the one line that says it, and that nothing else on stderr
is a traceback or a multi-kilobyte list.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from inputs.dataflash_writer import battery_log

from codegen.cli.main import main
from generated._ulog_writer import write as ulog_write
from generated.uorb import BatteryInfo as UorbBatteryInfo

MISSING = "cannot read file: no such file or directory"
LONGEST_LINE = 300  # characters: an error is a sentence, not the list of every known name


def _flight_bin(folder: Path) -> None:
    """An ArduPilot DataFlash log with PARM, ARM and BAT records: a flight log, not a file of records."""
    rows = [(t / 10, 0, 12.0 - t / 100, 5.0, t * 1.5) for t in range(20)]
    battery_log(folder / "flight.bin", {"BATT_MONITOR": 4, "BATT_CAPACITY": 3300}, rows, [(0.5, True)])


def _log_without_batteries(folder: Path) -> None:
    """A readable DataFlash log with its PARM and ARM records but no BAT record, and a PX4 ULog without
    battery_status: a log the failsafe and the report have nothing to replay or draw from."""
    battery_log(folder / "nobat.bin", {"BATT_MONITOR": 4, "BATT_CAPACITY": 3300}, [], [(0.5, True)])
    ulog_write(folder / "nobat.ulg", [], info={"sys_name": "PX4"}, messages=[UorbBatteryInfo])


def _capture(folder: Path, name: str, lines: list[str]) -> None:
    (folder / name).write_text("".join(f"({1700000000 + i / 10:.6f}) can0 {x}\n" for i, x in enumerate(lines)))


BATTERY_PARAMS = "BATT_MONITOR,4\nBATT_CAPACITY,3300\nBATT_LOW_VOLT,10.5\n"


@dataclass(frozen=True)
class Case:
    """One wrong input: the files it needs (name -> text, or a function writing them), the command, the exit
    code, and the text of the one line that must say what is wrong."""

    id: str
    argv: tuple[str, ...]
    code: int
    says: str
    files: dict[str, str] = field(default_factory=dict)
    make: Callable[[Path], None] | None = None
    needs: str | None = None  # an optional dependency the case needs (an extra)


CASES = [
    # a missing file: one wording, whichever command and reader meets it
    Case("failsafe-missing-log", ("failsafe", "nope.bin"), 2, f"nope.bin: {MISSING}"),
    Case(
        "failsafe-missing-params",
        ("failsafe", "--params", "nope.param", "s.jsonl"),
        2,
        f"nope.param: {MISSING}",
        {"s.jsonl": ""},
    ),
    Case("validate-missing-dts", ("validate", "--message", "simple-battery", "nope.dts"), 2, f"nope.dts: {MISSING}"),
    Case("params-missing-dts", ("params", "--from-devicetree", "nope.dts"), 2, f"nope.dts: {MISSING}"),
    Case("params-check-missing", ("params", "--check", "nope.param"), 2, f"nope.param: {MISSING}"),
    Case(
        "convert-missing", ("convert", "--from", "dronecan", "--to", "uorb", "nope.jsonl"), 2, f"nope.jsonl: {MISSING}"
    ),
    Case("report-missing", ("report", "nope.ulg"), 2, f"nope.ulg: {MISSING}"),
    Case("can-missing", ("can", "nope.log"), 2, f"nope.log: {MISSING}"),
    Case("export-missing", ("export", "nope.ulg", "-o", "ds"), 1, f"nope.ulg: {MISSING}", needs="pyarrow"),
    # names: a short did-you-mean, never every known name
    Case(
        "convert-misspelt-from",
        ("convert", "--from", "dronecn", "--to", "uorb", "x.jsonl"),
        2,
        "--from 'dronecn': expected a format or message, found no such name; did you mean 'dronecan'?",
        {"x.jsonl": "{}\n"},
    ),
    Case(
        "validate-misspelt-message",
        ("validate", "--message", "BatteryStatu", "x.jsonl"),
        2,
        "no message called 'BatteryStatu' in the schemas; did you mean 'BatteryStatus'",
        {"x.jsonl": "{}\n"},
    ),
    Case(
        "convert-misspelt-to",
        ("convert", "--from", "dronecan", "--to", "uorbb", "x.jsonl"),
        2,
        "--to 'uorbb': expected a format or message, found no such name; did you mean 'uorb' or 'uorb_v0'?",
        {"x.jsonl": "{}\n"},
    ),
    Case(
        "convert-missing-dts",
        ("convert", "--from", "dronecan", "--to", "uorb", "nope.dts"),
        2,
        f"nope.dts: {MISSING}",
    ),
    Case(
        "schema-unknown-message",  # no close name: how many there are (the names were once read twice from one pass)
        ("schema", "--message", "nope"),
        2,
        "no message called 'nope' in the schemas; ",
    ),
    # what a file is
    Case(
        "convert-dataflash-as-records",
        ("convert", "--from", "uorb", "--to", "mavlink", "flight.bin"),
        2,
        "flight.bin: expected a record file for --from uorb, found an ArduPilot DataFlash log",
        make=_flight_bin,
    ),
    Case(
        "convert-dataflash-without-can",
        ("convert", "--from", "ardupilot_battery", "--to", "uorb", "flight.bin"),
        1,
        "flight.bin (an ArduPilot DataFlash log: convert reads its CANF/CAFD CAN frames, and it has none)",
        make=_flight_bin,
    ),
    Case(
        "candump-numbered-line",
        ("can", "j1939.log"),
        2,
        "j1939.log:2: expected a candump -l line such as '(1612543138.000000) can0 123#DEADBEEF', found a line it "
        "cannot read",
        {"j1939.log": "(1.0) vcan0 0CF00400#0041FF20\n2 (1.1) vcan0 18F00400#00\n"},
    ),
    Case(
        "csv-capture-bad-row",
        ("can", "--input-format", "can", "bus.csv"),
        2,
        "bus.csv:2: expected a python-can CSV row (timestamp,arbitration_id,extended,remote,error,dlc,data), found a "
        "line it cannot read",
        {"bus.csv": "a,b\n1,2\n"},
        needs="can",
    ),
    # options the help documents are accepted
    Case(
        "can-input-format",
        ("can", "--input-format", "can", "bus.csv"),
        0,
        "bus.csv: 1 frames, 1 transfers",
        {"bus.csv": "timestamp,arbitration_id,extended,remote,error,dlc,data\n1.0,0x1004e37f,1,0,0,8,AAAAAAAAAMA=\n"},
        needs="can",
    ),
    # counts that add up, and frames that do not vanish
    Case(
        "validate-capture-counts",
        ("validate", "bad.log"),
        1,
        "1 error, 0 warnings (shown as 1 line)",
        make=lambda d: _capture(
            d, "bad.log", ["1004E37F#00000000000000C0", "1004E37F#0000000000000080", "1004E37F#0000000000000040"]
        ),
        needs="can",
    ),
    Case(
        "can-error-and-remote-frames",
        ("can", "ef.log"),
        0,
        "1 x can-error-frame",
        make=lambda d: _capture(d, "ef.log", ["1004E37F#00000000000000C0", "20000080#0000000000000000", "1004E37F#R"]),
        needs="can",
    ),
    Case(
        "can-remote-frames",
        ("can", "rf.log"),
        0,
        "1 x can-remote-frame",
        make=lambda d: _capture(d, "rf.log", ["1004E37F#00000000000000C0", "1004E37F#R"]),
        needs="can",
    ),
    # a readable input without what the command needs: 1, and 0 with --allow-empty
    Case(
        "export-empty",
        ("export", "empty.jsonl", "--message", "uorb.BatteryStatus", "-o", "ds"),
        1,
        "empty.jsonl: expected battery records, found none (--allow-empty accepts that)",
        {"empty.jsonl": ""},
        needs="pyarrow",
    ),
    Case(
        "export-empty-allowed",
        ("export", "--allow-empty", "empty.jsonl", "--message", "uorb.BatteryStatus", "-o", "ds"),
        0,
        "1 logs: 1 exported (0 rows)",
        {"empty.jsonl": ""},
        needs="pyarrow",
    ),
    Case(
        "failsafe-empty",
        ("failsafe", "--params", "v.param", "empty.jsonl"),
        1,
        "empty.jsonl: expected battery readings, found none (--allow-empty accepts that)",
        {"v.param": BATTERY_PARAMS, "empty.jsonl": ""},
    ),
    Case(
        "failsafe-empty-allowed",
        ("failsafe", "--allow-empty", "--params", "v.param", "empty.jsonl"),
        0,
        "empty.jsonl: no battery readings",
        {"v.param": BATTERY_PARAMS, "empty.jsonl": ""},
    ),
    Case(
        "failsafe-log-without-batteries",
        ("failsafe", "nobat.bin"),
        1,
        "nobat.bin: expected battery readings, found none (--allow-empty accepts that)",
        make=_log_without_batteries,
    ),
    Case(
        "failsafe-log-without-batteries-allowed",
        ("failsafe", "--allow-empty", "nobat.bin"),
        0,
        "nobat.bin: no battery readings",
        make=_log_without_batteries,
    ),
    Case(
        "failsafe-ulog-without-batteries",
        ("failsafe", "nobat.ulg"),
        1,
        "nobat.ulg: expected battery readings, found none (--allow-empty accepts that)",
        make=_log_without_batteries,
    ),
    Case(
        "failsafe-ulog-without-batteries-allowed",
        ("failsafe", "--allow-empty", "nobat.ulg"),
        0,
        "nobat.ulg: no battery readings",
        make=_log_without_batteries,
    ),
    Case(
        "report-log-without-batteries",
        ("report", "nobat.bin"),
        1,
        "nobat.bin: expected battery records, found none (--allow-empty accepts that)",
        make=_log_without_batteries,
        needs="plotly",
    ),
    Case(
        "report-empty",
        ("report", "--message", "uorb.BatteryStatus", "empty.jsonl"),
        1,
        "empty.jsonl: expected battery records, found none (--allow-empty accepts that)",
        {"empty.jsonl": ""},
        needs="plotly",
    ),
    Case(
        "report-empty-allowed",
        ("report", "--allow-empty", "--message", "uorb.BatteryStatus", "empty.jsonl"),
        0,
        "nothing to report, nothing written",
        {"empty.jsonl": ""},
        needs="plotly",
    ),
    # DroneCAN as upstream has it today: 127 is "unknown", not "above 100 %"
    Case(
        "validate-soc-unknown",
        ("validate", "--message", "power.BatteryInfo", "soc.jsonl"),
        0,
        "1 record in 1 file, 0 errors",
        {"soc.jsonl": '{"voltage": 12.0, "state_of_charge_pct": 127}\n'},
    ),
    # a devicetree character a web page pasted in: named, not "end of file"
    Case(
        "dts-stray-character",
        ("params", "--from-devicetree", "b.dts"),
        2,
        "b.dts:3: expected a property or child node name, found the character '\\xa0'",
        {"b.dts": '/dts-v1/;\n/ {\n\u00a0\n\tbattery { compatible = "simple-battery"; };\n};\n'},
    ),
    # the README's Dask example without a scheduler there: one line, in seconds
    Case(
        "dask-no-scheduler",
        ("export", "s.jsonl", "-o", "ds", "--engine", "dask", "--scheduler", "tcp://127.0.0.1:9"),
        2,
        "--scheduler tcp://127.0.0.1:9: expected a Dask scheduler there, found none within 5 s",
        {"s.jsonl": ""},
        needs="distributed",
    ),
]


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_wrong_input_is_one_line_and_the_documented_exit_code(
    case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    if case.needs is not None:
        pytest.importorskip(case.needs)
    for name, text in case.files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    if case.make is not None:
        case.make(tmp_path)
    monkeypatch.chdir(tmp_path)  # the names as a user types them, relative to where they stand
    code = main(list(case.argv))
    out, err = capsys.readouterr()
    lines = (out + err).splitlines()
    assert code == case.code, err
    saying = [x for x in lines if case.says in x]
    assert len(saying) == 1, lines  # said once, on one line
    assert "Traceback" not in err and all(len(x) <= LONGEST_LINE for x in err.splitlines()), err
    assert ":0:" not in err  # no fake line 0
    assert not any(x.rstrip().endswith(":") for x in lines)  # no sentence cut before what it announces
