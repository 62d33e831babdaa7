"""`battgen validate` and `battgen convert` on flight and telemetry logs: PX4 ULog (.ulg),
MAVLink .tlog and raw MAVLink streams (.mav / --input-format mavlink)."""

from __future__ import annotations

import json
import struct
import tracemalloc
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT
from shared_data import REAL_LOGS, missing

from codegen.apps.gate.validate import make_checker
from codegen.cli.main import main
from codegen.cli.validate import check_file
from codegen.inputs.dispatch import read_records
from generated import _ulog
from generated.mavlink import BatteryStatus as MavBattery
from generated.uorb import BatteryStatus

SCHEMAS = ROOT / "schemas"


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[str], str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, [line for line in out.splitlines() if line], err


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict[str, Any]]:
    code = main(["validate", "--format", "json", *args])
    return code, json.loads(capsys.readouterr().out)


# -- ULog --------------------------------------------------------------------------------------


def _record(kind: str, body: bytes) -> bytes:
    return struct.pack("<HB", len(body), ord(kind)) + body


def old_format_log(path: Path, rows: list[tuple[int, float, float, int]]) -> None:
    """A log whose battery_status lacks most fields (max_error, cell_count, voltage_cell_v...)."""
    fmt = b"battery_status:uint64_t timestamp;float voltage_v;float remaining;uint8_t warning;uint8_t[3] _padding0;"
    out = _ulog.MAGIC + bytes((1,)) + struct.pack("<Q", 0) + _record("B", bytes(40)) + _record("F", fmt)
    out += _record("A", struct.pack("<BH", 0, 0) + b"battery_status")
    for row in rows:
        out += _record("D", struct.pack("<H", 0) + struct.pack("<QffB", *row))
    path.write_bytes(out)


def test_fields_the_log_lacks_are_not_blamed_on_it(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "old.ulg"
    old_format_log(path, [(1000, 12.0, 0.5, 0), (2000, 11.9, 1.5, 0), (3000, 11.8, 0.4, 9)])
    code, lines, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(path))
    assert code == 1
    # max_error is 0 by default, outside [1, 100]: not reported, since the log has no max_error
    assert lines == [
        f"{path.as_posix()}: battery_status multi_id 0, timestamp 2000 us, offset 207: remaining = 1.5 is above the "
        "maximum 1",
        f"{path.as_posix()}: battery_status multi_id 0, timestamp 3000 us, offset 229: warning = 9 is not one of "
        "WARNING_NONE (0), WARNING_LOW (1), WARNING_CRITICAL (2), WARNING_EMERGENCY (3), WARNING_FAILED (4), "
        "STATE_UNHEALTHY (6), STATE_CHARGING (7)",
    ]
    assert err.count("the log's format differs") == 1 and err.count("not checked") == 1
    assert "max_error" in err.split("not checked")[1]
    data = path.read_bytes()
    assert data[207 + 2] == ord("D") and data[229 + 2] == ord("D")  # offsets name the 'D' records


def test_real_px4_logs_predating_message_versions(capsys: pytest.CaptureFixture[str]) -> None:
    path = REAL_LOGS / "sample_log_small.ulg"
    if not path.is_file():
        missing("the shared real PX4 logs")
    code, doc = run_json(capsys, "--message", "uorb.BatteryStatus", "--profile", "", str(path))  # no px4 waivers
    report = doc["files"][0]
    assert code == 1 and report["records"] == 42  # 21 records of each of two batteries
    kinds = [n["kind"] for n in report["notices"]]
    assert kinds == ["format-diff", "unchecked"]
    diff = report["notices"][0]["data"]
    assert ["voltage_cell_v", "float[14]", "float[10]"] in diff["converted"] and diff["retyped"] == []
    assert diff["renamed"] == [["average_current_a", "current_average_a"]]
    unchecked = report["notices"][1]["data"]["fields"]
    assert "time_remaining_s" in unchecked and not {"cell_count", "voltage_cell_v"} & set(unchecked)
    multi_ids = [v["location"]["multi_id"] for v in report["violations"]]
    assert set(multi_ids) == {0, 1} and multi_ids[:2] == [0, 1]  # file order: batteries interleaved
    stamps = [v["location"]["timestamp_us"] for v in report["violations"] if v["location"]["multi_id"] == 0]
    assert stamps == sorted(stamps) and stamps[0] == 20630667
    # max_error is in these logs, and 0 there: a real finding; nothing about fields the log lacks
    assert {v["path"] for v in report["violations"]} == {"max_error"}


def test_identical_format_log_with_two_instances(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "new.ulg"
    rows = []
    for i in range(6):
        ok = BatteryStatus(timestamp=100 * i, voltage_v=12.0, remaining=0.5, max_error=1, cell_count=3)
        ok.voltage_cell_v = [4.0, 4.0, 4.0] + [0.0] * 11
        rows.append((ok, i % 2))
    rows[3][0].voltage_cell_v[5] = 3.3  # cell beyond cell_count: a cross-field rule
    _ulog.write(path, rows)
    code, doc = run_json(capsys, "--message", "uorb.BatteryStatus", str(path))
    report = doc["files"][0]
    assert (code, report["records"], report["notices"]) == (1, 6, [])
    [v] = report["violations"]
    assert v["rule"] == "cross-field:cells-beyond-count-zero"
    assert {k: v["location"][k] for k in ("topic", "multi_id", "timestamp_us")} == {
        "topic": "battery_status",
        "multi_id": 1,
        "timestamp_us": 300,
    }


def test_ulog_errors_exit_2_in_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "junk.ulg"
    path.write_bytes(b"not a log at all, just text\n")
    code, lines, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(path))
    assert code == 2 and lines == [] and "Traceback" not in err
    assert f"{path.as_posix()}: expected a ULog file: not a ULog file" in err
    code, _, err = run(capsys, "validate", "--message", "mavlink.BATTERY_STATUS", str(path))
    assert code == 2 and "a ULog file holds uORB topics, but mavlink.BATTERY_STATUS is a mavlink message" in err


def test_log_without_the_topic_has_no_records(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "v0.ulg"
    from generated.uorb import BatteryStatusV0

    _ulog.write(path, [BatteryStatusV0()])
    code, lines, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(path))
    assert (code, lines) == (1, [])  # nothing checked is not a pass
    assert "warning: no battery_status records in this log (topics logged: battery_status_v0)" in err
    assert f"{path.as_posix()}: no uorb.BatteryStatus records in this file (--allow-empty accepts that)" in err
    code, lines, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", "--allow-empty", str(path))
    assert (code, lines) == (0, [])
    # convert reports the same, after the (empty) output
    code, lines, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(path))
    assert (code, lines) == (1, [])
    assert "warning: no battery_status records in this log (topics logged: battery_status_v0)" in err
    assert f"{path}: no records to convert" in err


def test_ulog_validation_memory_does_not_grow_with_records(tmp_path: Path) -> None:
    """The file is mapped and walked once, records decoded one at a time: the peak stays flat from
    3,000 to 15,000 records (an offset index would add ~40 bytes a record, a list of instances ~1 kB)."""
    message, checker = make_checker(SCHEMAS, "uorb.BatteryStatus")
    good = BatteryStatus(timestamp=1, voltage_v=12.0, remaining=0.5, max_error=1)
    peaks = []
    for n in (3_000, 15_000):
        path = tmp_path / f"long{n}.ulg"
        with _ulog.Writer(path, messages=[BatteryStatus]) as w:
            for i in range(n):
                good.timestamp = i
                w.write(good, multi_id=i % 3 % 2)
        tracemalloc.start()
        try:
            report = check_file(path, message, checker, echo=False)
            peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
        assert (report.records, report.errors, report.notices) == (n, 0, [])
    assert peaks[1] < 600_000 and peaks[1] < peaks[0] * 1.25 + 20_000, peaks


def test_damage_is_told_after_the_records(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "cut.ulg"
    _ulog.write(path, [BatteryStatus(timestamp=i, max_error=1) for i in range(3)])
    stray = _record("D", struct.pack("<H", 7) + b"abc")  # msg_id 7 was never subscribed
    path.write_bytes(path.read_bytes() + stray + _record("D", bytes(168))[:40])  # and a record cut short
    code, doc = run_json(capsys, "--message", "uorb.BatteryStatus", str(path))
    report = doc["files"][0]
    assert (code, report["records"]) == (0, 3)
    assert [n["kind"] for n in report["notices"]] == ["damage"] * 2
    assert "data for msg_id 7 without a subscription" in report["notices"][0]["message"]
    assert "truncated record 'D' at offset" in report["notices"][1]["message"]
    code, _, err = run(capsys, "validate", "--message", "uorb.BatteryStatus", str(path))
    assert code == 0 and err.count("warning: damaged log, recovered:") == 2
    message, checker = make_checker(SCHEMAS, "uorb.BatteryStatus")
    items = [getattr(item, "kind", "record") for item in read_records(path, message, model=checker.cls)]
    assert items == ["record"] * 3 + ["damage"] * 2  # known once the walk has seen the whole file


def test_convert_ulog_to_mavlink(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "conv.ulg"
    _ulog.write(path, [(BatteryStatus(voltage_v=12.6, id=i + 1, remaining=0.5), i) for i in range(3)])
    code, lines, err = run(
        capsys, "convert", "--from", "uorb.BatteryStatus", "--to", "mavlink.BATTERY_STATUS", str(path)
    )
    assert code == 0, err
    records = [json.loads(line) for line in lines]
    assert [r["id"] for r in records] == [0, 1, 2] and records[0]["battery_remaining"] == 50
    old = tmp_path / "old.ulg"
    old_format_log(old, [(1000, 12.0, 0.5, 0)])
    code, lines, err = run(capsys, "convert", "--from", "uorb", "--to", "mavlink", str(old))
    assert code == 0 and len(lines) == 1
    assert "the log's format differs" in err and "not in the log, converted from the schema's defaults" in err


# -- MAVLink logs ---------------------------------------------------------------------------------


def _other_frame(seq: int) -> bytes:
    """A MAVLink 2 frame of ATTITUDE (id 30): a message this package does not know (HEARTBEAT it does)."""
    payload = bytes(9)
    return struct.pack("<BBBBBBBHB", 0xFD, len(payload), 0, 0, seq, 1, 1, 30, 0) + payload + b"\x12\x34"


def mavlink_log(tlog: bool) -> tuple[bytes, int]:
    out = bytearray()
    seq = 0
    for i in range(8):
        for frame in (
            _other_frame(seq),
            MavBattery(id=i, battery_remaining=120 if i == 5 else 50).encode_frame(seq=seq),
        ):
            if i == 2 and frame[0] == 0xFD and frame[7] == 147:
                frame = frame[:-1] + bytes((frame[-1] ^ 1,))  # bad CRC
            out += (struct.pack(">Q", 1_000_000 * (i + 1)) if tlog else b"") + frame
            seq += 1
        if i == 4:
            out += b"\x00garbage\x00"
    return bytes(out), 7


def test_tlog_records_damage_summary_and_locations(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "flight.tlog"
    path.write_bytes(mavlink_log(tlog=True)[0])
    code, lines, err = run(capsys, "validate", str(path))
    assert code == 1
    [line] = lines
    assert line.startswith(f"{path.as_posix()}: BATTERY_STATUS #4 from 1/1 seq 10 at 6000000 us, offset ")
    assert "battery_remaining = 120" in line
    assert "warning: 7 BATTERY_STATUS records, 8 frames of other messages skipped, 1 BATTERY_STATUS frames" in err
    assert "9 bytes of garbage skipped" in err
    code, doc = run_json(capsys, str(path))
    [v] = doc["files"][0]["violations"]
    assert v["location"]["timestamp_us"] == 6_000_000 and v["location"]["seq"] == 10


def test_raw_mavlink_stream_through_the_stream_parser(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    data, records = mavlink_log(tlog=False)
    path = tmp_path / "capture.bin"  # .bin is DataFlash: the format must be given
    path.write_bytes(data)
    code, _, err = run(capsys, "validate", str(path))
    assert code == 2 and "--message is required" in err
    code, doc = run_json(capsys, "--input-format", "mavlink", "--message", "mavlink.BATTERY_STATUS", str(path))
    report = doc["files"][0]
    assert (code, report["records"]) == (1, records)
    [notice] = report["notices"]
    assert notice["data"]["bad_crc"] == 1 and notice["data"]["garbage_bytes"] >= 9
    assert report["violations"][0]["location"]["frame"] == 4
    (tmp_path / "capture.mav").write_bytes(data)
    code, lines, err = run(capsys, "convert", "--from", "mavlink", "--to", "uorb", str(tmp_path / "capture.mav"))
    assert code == 2 and "cannot convert (--policy strict)" in err  # strict refuses the record validate refuses
    mav = str(tmp_path / "capture.mav")
    code, lines, err = run(capsys, "convert", "--from", "mavlink", "--to", "uorb", "--policy", "px4", mav)
    assert code == 0 and len(lines) == records and "1 BATTERY_STATUS frames with a bad CRC" in err


def test_nothing_mavlink_is_unreadable(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    for name in ("noise.tlog", "noise.mav"):
        path = tmp_path / name
        path.write_bytes(bytes(range(0, 250)) * 4)
        code, lines, err = run(capsys, "validate", str(path))
        assert code == 2 and lines == [] and "Traceback" not in err
        assert f"{path.as_posix()}:" in err and "expected a MAVLink" in err
    empty = tmp_path / "empty.tlog"
    empty.write_bytes(b"")
    code, _, err = run(capsys, "validate", str(empty))
    assert code == 1 and "0 records" in err and "no mavlink.BATTERY_STATUS records in this file" in err
