"""The DataFlash (.bin) reader (codegen.inputs.dataflash.log) on logs written by an independent writer
(tests/inputs/dataflash_writer.py, from the format's description), read through pymavlink."""

from __future__ import annotations

from pathlib import Path

import pytest
from dataflash_writer import DataflashWriter, battery_log

from codegen.inputs.dataflash import log as dataflash
from codegen.inputs.records import InputError

PARAMS = {"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 2, "BATT2_CRT_VOLT": 9.9}
ROWS = [(1.0, 0, 12.4, 5.5, 120.0), (1.0, 1, 12.1, 1.5, 40.0), (2.0, 0, 10.4, 6.0, 2500.0)]


def test_messages_parameters_batteries_and_arming(tmp_path: Path) -> None:
    path = battery_log(tmp_path / "flight.bin", PARAMS, ROWS, [(0.5, True), (3.0, False)])
    log = dataflash.open_log(path)
    assert dataflash.log_parameters(log) == {"BATT_LOW_VOLT": 10.5, "BATT_FS_LOW_ACT": 2.0, "BATT2_CRT_VOLT": 9.9}
    items = list(dataflash.flight_records(log))
    assert [type(i).__name__ for i in items] == ["ArmingRecord", "BatteryRecord", "BatteryRecord", "BatteryRecord",
                                                 "ArmingRecord"]  # fmt: skip
    bats = list(dataflash.battery_records(log))
    assert [(b.time_s, b.instance, b.voltage_v, b.current_a, b.consumed_mah) for b in bats] == [
        (t, i, v, a, m) for t, i, v, a, m in ROWS
    ]  # float32 values come back as the decimals written
    assert [(a.time_s, a.armed) for a in dataflash.arming_records(log)] == [(0.5, True), (3.0, False)]
    types = [m.type for m in log.messages()]
    assert types[:4] == ["FMT"] * 4 and types.count("PARM") == 3 and types.count("BAT") == 3
    offsets = [m.offset for m in log.messages()]
    assert offsets == sorted(offsets) and offsets[0] == 0 and offsets[1] == 89  # FMT is 89 bytes long
    assert log.skipped_notes == []


def test_a_parameter_logged_twice_takes_its_last_value(tmp_path: Path) -> None:
    w = DataflashWriter()
    w.define("PARM", "QNf", ("TimeUS", "Name", "Value"))
    w.write("PARM", 0, "BATT_LOW_VOLT", 10.5)
    w.write("PARM", 5_000_000, "BATT_LOW_VOLT", 10.8)  # changed in flight
    log = dataflash.open_log(w.save(tmp_path / "p.bin"))
    assert dataflash.log_parameters(log) == {"BATT_LOW_VOLT": 10.8}


def test_older_layouts_bat_without_instance_and_bat2(tmp_path: Path) -> None:
    w = DataflashWriter()
    w.define("BAT", "Qfffff", ("TimeUS", "Volt", "VoltR", "Curr", "CurrTot", "Temp"))
    w.define("BAT2", "Qfffff", ("TimeUS", "Volt", "VoltR", "Curr", "CurrTot", "Temp"))
    w.define("EV", "QB", ("TimeUS", "Id"))
    w.write("EV", 1_000, 10)
    w.write("BAT", 2_000, 11.1, 11.1, 3.0, 10.0, 0.0)
    w.write("BAT2", 2_000, 12.2, 12.2, 1.0, 5.0, 0.0)
    w.write("EV", 3_000, 11)
    log = dataflash.open_log(w.save(tmp_path / "old.bin"))
    assert [(b.instance, b.voltage_v) for b in dataflash.battery_records(log)] == [(0, 11.1), (1, 12.2)]
    assert [a.armed for a in dataflash.arming_records(log)] == [True, False]


def test_garbage_between_messages_is_skipped_and_noted(tmp_path: Path) -> None:
    w = DataflashWriter()
    w.define("EV", "QB", ("TimeUS", "Id"))
    w.write("EV", 1_000, 10)
    w.out += b"\x00\x01garbage" * 80
    w.write("EV", 2_000, 11)
    w.out += b"x" * 600  # pymavlink only reports skipped bytes with >= 528 bytes left
    w.write("EV", 3_000, 10)
    log = dataflash.open_log(w.save(tmp_path / "g.bin"))
    assert [a.time_s for a in dataflash.arming_records(log)] == [0.001, 0.002, 0.003]
    assert log.skipped_notes and "Skipped" in log.skipped_notes[0]


def test_a_message_its_damaged_format_does_not_describe_is_skipped(tmp_path: Path) -> None:
    """Found by tests/fuzz/test_fuzz_failsafe_inputs.py: one byte inserted into a FMT record made
    pymavlink's DFMessage.to_dict raise IndexError."""
    good = battery_log(tmp_path / "g.bin", {"BATT_LOW_VOLT": 10.5}, [(1.0, 0, 12.0, 1.0, 5.0)], [(0.5, True)])
    data = good.read_bytes()
    bad = tmp_path / "bad.bin"
    bad.write_bytes(data[:203] + b"," + data[203:])
    log = dataflash.open_log(bad)
    list(dataflash.flight_records(log))
    assert any("cannot decode" in note for note in log.skipped_notes)


@pytest.mark.parametrize(
    ("content", "expected"),
    [(b"", "empty file"), (b"PK\x03\x04 not a log", "A3 95 80"), (b"\xa3\x95\x80\x01", "")],
)
def test_unreadable_files_are_input_errors(tmp_path: Path, content: bytes, expected: str) -> None:
    path = tmp_path / "bad.bin"
    path.write_bytes(content)
    try:
        log = dataflash.open_log(path)
        messages = list(log.messages())
    except InputError as exc:
        assert exc.file == path.as_posix() and expected in exc.message
    else:  # a lone cut-off FMT header: nothing to read, no crash
        assert expected == "" and messages == []


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="cannot read file"):
        dataflash.open_log(tmp_path / "absent.bin")
    assert not dataflash.is_dataflash(tmp_path / "absent.bin")
