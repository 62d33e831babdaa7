"""The generated ULog runtime: the file our writer produces, and the reader on good and damaged logs."""

from __future__ import annotations

import io
import mmap
import struct
import tracemalloc
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from shared_data import REAL_LOGS, missing

from codegen.frontends import uorb
from generated import _ulog
from generated.uorb import BatteryStatus, BatteryStatusV0

# PX4's definition of battery_status v1 as its logger writes it (fields sorted by size, padded to 8).
BATTERY_STATUS_FORMAT = (
    "battery_status:uint64_t timestamp;float voltage_v;float current_a;float current_average_a;"
    "float discharged_mah;float remaining;float scale;float time_remaining_s;float temperature;"
    "float[14] voltage_cell_v;float max_cell_voltage_delta;float full_charge_capacity_wh;"
    "float remaining_capacity_wh;float nominal_voltage;float internal_resistance_estimate;float ocv_estimate;"
    "float ocv_estimate_filtered;float volt_based_soc_estimate;float voltage_prediction;float prediction_error;"
    "float estimation_covariance_norm;uint16_t capacity;uint16_t cycle_count;uint16_t average_time_to_empty;"
    "uint16_t manufacture_date;uint16_t state_of_health;uint16_t max_error;uint16_t interface_error;"
    "uint16_t faults;uint16_t over_discharge_count;bool connected;uint8_t cell_count;uint8_t source;"
    "uint8_t priority;uint8_t id;bool is_powering_off;bool is_required;uint8_t warning;uint8_t[2] _padding0;"
)
NESTED = {
    "Inner.msg": "uint64 timestamp\nfloat32 x\nuint8 flag\nchar[5] tag\nint16[3] v\n",
    "Outer.msg": "uint64 timestamp\nInner one\nInner[2] many\nuint8 n\n",
}


def rec(kind: str, body: bytes) -> bytes:
    return struct.pack("<HB", len(body), ord(kind)) + body


def head(timestamp: int = 0, incompat: int = 0, offsets: tuple[int, ...] = ()) -> bytes:
    flags = bytes(8) + bytes((incompat,)) + bytes(7) + struct.pack("<3Q", *(*offsets, 0, 0, 0)[:3])
    return _ulog.MAGIC + b"\x01" + struct.pack("<Q", timestamp) + rec("B", flags)


def sub(multi_id: int, msg_id: int, topic: str) -> bytes:
    return rec("A", struct.pack("<BH", multi_id, msg_id) + topic.encode())


def data(msg_id: int, payload: bytes) -> bytes:
    return rec("D", struct.pack("<H", msg_id) + payload)


def battery_log(*extra_records: bytes, count: int = 3) -> bytes:
    """A hand-built log: battery_status records with timestamps 0..count-1, then ``extra_records``."""
    records = [data(0, BatteryStatus(timestamp=i).encode()[:166]) for i in range(count)]
    return (
        head()
        + rec("F", BATTERY_STATUS_FORMAT.encode())
        + sub(0, 0, "battery_status")
        + b"".join(records)
        + b"".join(extra_records)
    )


def split(raw: bytes) -> list[tuple[str, bytes]]:
    out, pos = [], 16
    while pos < len(raw):
        size, kind = struct.unpack_from("<HB", raw, pos)
        out.append((chr(kind), raw[pos + 3 : pos + 3 + size]))
        pos += 3 + size
    return out


@pytest.fixture
def nested(import_generated: Any, tmp_path: Path) -> ModuleType:
    src = tmp_path / "msg"
    src.mkdir()
    for name, text in NESTED.items():
        (src / name).write_text(text, encoding="utf-8")
    module: ModuleType = import_generated(uorb.parse_dir(src), "uorb")
    return module


def test_writer_produces_px4_records() -> None:
    out = io.BytesIO()
    with _ulog.Writer(out, timestamp=77, info={"sys_name": "battgen"}, parameters={"BAT1_N_CELLS": 4}) as w:
        w.write(BatteryStatus(timestamp=1, voltage_v=12.0))
        w.write(BatteryStatus(timestamp=2, voltage_v=16.0), multi_id=1)
        w.write(BatteryStatus(timestamp=3, voltage_v=12.5))
    raw = out.getvalue()
    assert raw[:8] == b"ULog\x01\x12\x35\x01" and struct.unpack_from("<Q", raw, 8)[0] == 77
    records = split(raw)
    assert records[0] == ("B", bytes(40))
    assert [k for k, _ in records] == ["B", "I", "P", "F", "A", "D", "A", "D", "D"]
    assert records[1][1] == b"\x10char[7] sys_namebattgen" and records[2][1] == b"\x14int32_t BAT1_N_CELLS\x04\0\0\0"
    assert records[3][1].decode() == BATTERY_STATUS_FORMAT
    assert records[4][1] == b"\x00\x00\x00battery_status" and records[6][1] == b"\x01\x01\x00battery_status"
    assert [len(body) for kind, body in records if kind == "D"] == [168, 168, 168]  # msg_id + 166: no trailing pad
    assert (
        records[7][1][:2] == b"\x01\x00"
        and records[5][1][2:] == BatteryStatus(timestamp=1, voltage_v=12.0).encode()[:166]
    )


def test_nested_formats_precede_their_users(nested: ModuleType) -> None:
    out = io.BytesIO()
    nested._ulog.write(out, [nested.Outer(timestamp=5)])
    formats = [body.decode() for kind, body in split(out.getvalue()) if kind == "F"]
    assert formats == [
        "inner:uint64_t timestamp;float x;int16_t[3] v;uint8_t flag;char[5] tag;",
        "outer:uint64_t timestamp;uint8_t n;uint8_t[7] _padding0;inner one;inner[2] many;",
    ]


def test_read_back_what_was_written(nested: ModuleType) -> None:
    a, b = nested.Outer(timestamp=1, n=7), nested.Outer(timestamp=2)
    a.one.tag, a.many[1].v = "hi", [1, 2, 3]
    out = io.BytesIO()
    with nested._ulog.Writer(out, info={"ver_hw": "X", "time_ref_utc": 3600, "scale": 0.5}) as w:
        w.write(a)
        w.write(b, multi_id=2)
        w.log("armed", timestamp=9)
    log = nested._ulog.read(out.getvalue())
    assert log.topics() == [("outer", 0), ("outer", 2)] and log.count("outer", 2) == 1 and log.count("outer", 1) == 0
    assert log.info == {"ver_hw": "X", "time_ref_utc": 3600, "scale": 0.5} and log.logged == [(54, 9, "armed")]
    assert log.messages(nested.Outer) == [a] and log.messages(nested.Outer, multi_id=2) == [b]
    records = nested.Outer.from_ulog(out.getvalue())  # every instance, each record saying which
    assert [(r.multi_id, r.instance) for r in records] == [(0, a), (2, b)]
    assert [r.instance for r in nested.Outer.from_ulog(out.getvalue(), multi_id=2)] == [b]
    cols = log.columns("outer", use_numpy=False)
    assert cols["one.tag"] == [b"hi\0\0\0"] and cols["many[1].v[2]"] == [3] and cols["n"] == [7]
    assert log.compare(nested.Outer).identical and not log.warnings


def test_writer_refuses_late_definitions_and_bad_values() -> None:
    w = _ulog.Writer(io.BytesIO())
    w.write(BatteryStatus())
    with pytest.raises(_ulog.ULogError, match=r"define BatteryStatusV0 \(battery_status_v0\) before the first record"):
        w.write(BatteryStatusV0())
    with pytest.raises(_ulog.ULogError, match=r"multi_id must be 0\.\.255, got 256"):
        w.write(BatteryStatus(), multi_id=256)
    w.close()
    with pytest.raises(_ulog.ULogError, match=r"info: expected a str, bool, int or float value, got \[1\]"):
        _ulog.Writer(io.BytesIO(), info={"info": [1]}).close()  # type: ignore[dict-item]


def test_one_class_under_two_topics() -> None:
    out = io.BytesIO()
    with _ulog.Writer(out) as w:
        w.define(BatteryStatusV0, "battery_status")
        w.write(BatteryStatusV0(timestamp=4, serial_number=9), topic="battery_status")
    log = _ulog.read(out.getvalue())
    assert log.messages(BatteryStatusV0, topic="battery_status")[0].serial_number == 9
    diff = log.compare(BatteryStatus)
    assert diff.extra == (("serial_number", "uint16_t"),) and not diff.missing and not diff.identical


def test_truncated_last_record_warns_and_keeps_the_rest() -> None:
    raw = battery_log()[:-10]
    with pytest.warns(_ulog.ULogWarning, match=r"truncated record 'D' at offset \d+: 158 of 168 bytes at the end"):
        log = _ulog.read(raw)
    assert log.count("battery_status") == 2 and len(log.warnings) == 1
    with pytest.warns(_ulog.ULogWarning, match=r"truncated record header at offset \d+: 2 bytes at the end"):
        assert _ulog.read(battery_log() + b"\x05\x00").count("battery_status") == 3


def test_unknown_record_types_are_skipped() -> None:
    log = _ulog.read(battery_log(rec("Z", b"future"), data(0, BatteryStatus(timestamp=9).encode()[:166])))
    assert log.unknown_types == {"Z": 1} and not log.warnings
    assert [m.timestamp for m in log.messages(BatteryStatus)] == [0, 1, 2, 9]


def test_corrupt_header_resyncs_at_the_next_sync_record() -> None:
    sync = rec("S", _ulog.SYNC)
    raw = battery_log(b"\0\0\0garbage", sync, data(0, BatteryStatus(timestamp=7).encode()[:166]))
    with pytest.warns(_ulog.ULogWarning, match=r"corrupt record header at offset \d+, resynced at \d+"):
        log = _ulog.read(raw)
    assert [m.timestamp for m in log.messages(BatteryStatus)] == [0, 1, 2, 7]


def test_appended_data_resumes_at_the_offset() -> None:
    """A crash left half a record; the data appended after it starts at the flagged offset."""
    body = rec("F", BATTERY_STATUS_FORMAT.encode()) + sub(0, 0, "battery_status")
    body += data(0, BatteryStatus(timestamp=1).encode()[:166])
    cut = data(0, BatteryStatus(timestamp=2).encode()[:166])[:50]
    start = len(head()) + len(body) + len(cut)
    raw = head(incompat=_ulog.INCOMPAT_DATA_APPENDED, offsets=(start,)) + body + cut
    raw += data(0, BatteryStatus(timestamp=3).encode()[:166])
    with pytest.warns(_ulog.ULogWarning, match="before an appended-data offset"):
        log = _ulog.read(raw)
    assert log.appended_offsets == (start,) and [m.timestamp for m in log.messages(BatteryStatus)] == [1, 3]


def test_unknown_incompatible_flags_refuse_the_log() -> None:
    raw = head(incompat=0x02) + rec("F", BATTERY_STATUS_FORMAT.encode())
    with pytest.raises(_ulog.ULogError, match="unknown incompatible flag bits 0200000000000000"):
        _ulog.read(raw)


def test_not_a_ulog_file() -> None:
    with pytest.raises(_ulog.ULogError, match="not a ULog file: expected the magic bytes"):
        _ulog.read(b"PNG\0" * 8)


def test_bad_data_records_are_skipped_with_one_warning_per_id() -> None:
    with pytest.warns(_ulog.ULogWarning) as caught:
        log = _ulog.read(battery_log(data(9, b"x" * 8), data(9, b"y" * 8), data(0, bytes(100))))
    messages = [str(w.message) for w in caught]
    assert messages[0].startswith("data for msg_id 9 without a subscription (first at offset")
    assert "data of 100 bytes for msg_id 0" in messages[1] and "expected 166, skipped" in messages[1]
    assert len(messages) == 2 and log.skipped_records == 3 and log.count("battery_status") == 3


def test_bad_definitions_are_reported() -> None:
    raw = head() + rec("F", b"no colon here") + rec("F", b"t:uint8_t[x] a;") + rec("F", b"u:mystery m;")
    raw += sub(0, 0, "u")
    with pytest.warns(_ulog.ULogWarning) as caught:
        log = _ulog.read(raw)
    messages = [str(w.message) for w in caught]
    assert "skipped a bad 'F' record" in messages[0] and "format definition without 'name:'" in messages[0]
    assert "format t: bad array type in 'uint8_t[x] a'" in messages[1]
    assert "subscription to 'u' (msg_id 0): format u: field m has unknown type 'mystery'" in messages[2]
    assert list(log.formats) == ["u"]
    with pytest.raises(_ulog.ULogError, match="no format for topic 'nope' in this log"):
        log.columns("nope")


def test_format_differences_inside_nested_types(nested: ModuleType) -> None:
    """The log's inner struct retypes x, drops flag and adds extra: the rest still decodes."""
    inner = "inner:uint64_t timestamp;double x;int16_t[3] v;char[5] tag;uint8_t extra;uint8_t[4] _padding0;"
    outer = "outer:uint64_t timestamp;uint8_t n;uint8_t[7] _padding0;inner one;inner[2] many;"
    formats = {f.name: f for f in map(_ulog.parse_format, (inner, outer))}
    lay = _ulog.layout(formats["outer"], formats)
    values = {n: b"" if c.endswith("s") else 0 for n, c in zip(lay.names, lay.codes, strict=True)}
    values |= {"n": 5, "one.x": 2.5, "one.tag": b"ab", "many[1].v[2]": -4}
    payload = struct.pack(lay.columns().fmt, *(values[n] for n in lay.names)).ljust(lay.data_size, b"\0")
    raw = head() + rec("F", inner.encode()) + rec("F", outer.encode()) + sub(0, 0, "outer") + data(0, payload)
    log = nested._ulog.read(raw)
    diff = log.compare(nested.Outer)
    assert diff.missing == (("one.flag", "uint8_t"), ("many.flag", "uint8_t"))
    assert diff.extra == (("one.extra", "uint8_t"), ("many.extra", "uint8_t"))
    assert [(r.name, r.schema, r.log) for r in diff.retyped] == [
        ("one.x", "float", "double"),
        ("many.x", "float", "double"),
    ]  # only top-level fields are converted (PX4 never retyped inside a nested type)
    assert not diff.identical and not diff.matches
    (record,) = log.iter_records(nested.Outer)
    assert dict(record.extras) == {"one.extra": 0, "many[0].extra": 0, "many[1].extra": 0}
    (msg,) = log.messages(nested.Outer)
    assert msg.n == 5 and msg.one.tag == "ab" and msg.one.x == 0.0 and msg.many[1].v == [0, 0, -4]
    assert isinstance(msg.many[0], nested.Inner) and str(diff).startswith("outer: the log's format differs")


def test_diff_text_and_data() -> None:
    small = battery_log().replace(b"uint16_t faults;", b"uint16_t faultz;")
    diff = _ulog.read(small).compare(BatteryStatus)
    assert diff.to_dict() == {
        "topic": "battery_status",
        "message": "battery_status",
        "missing": [["faults", "uint16_t"]],
        "extra": [["faultz", "uint16_t"]],
        "retyped": [],
        "renamed": [],
        "converted": [],
        "identical": False,
    }
    assert str(diff) == (
        "battery_status: the log's format differs from the schema (battery_status)\n"
        "  missing from the log (left at defaults): faults uint16_t\n"
        "  only in the log (kept as extras): faultz uint16_t"
    )
    assert str(_ulog.read(battery_log()).compare(BatteryStatus)) == (
        "battery_status: the log's format is the schema's (battery_status)"
    )


# -- streaming: read(..., index=False), Log.iter_records ------------------------------------------


def scan(raw: bytes) -> list[tuple[int, int, str]]:
    """(offset, multi_id, topic) of every 'D' record, found by following the record sizes."""
    subs: dict[int, tuple[int, str]] = {}
    out, pos = [], 16
    while pos < len(raw):
        size, kind = struct.unpack_from("<HB", raw, pos)
        body = raw[pos + 3 : pos + 3 + size]
        if kind == ord("A"):
            subs[struct.unpack_from("<H", body, 1)[0]] = (body[0], body[3:].decode())
        elif kind == ord("D"):
            out.append((pos, *subs[struct.unpack_from("<H", body)[0]]))
        pos += 3 + size
    return out


def mixed_log(path: Path) -> list[tuple[BatteryStatus, int]]:
    """Two battery instances in an irregular order, with another topic and log text in between."""
    written = []
    with _ulog.Writer(path, messages=[BatteryStatus, BatteryStatusV0]) as w:
        for i in range(40):
            multi_id = 1 if i % 3 == 1 or i % 7 == 0 else 0
            msg = BatteryStatus(timestamp=i, voltage_v=10 + i / 8, id=multi_id)
            w.write(msg, multi_id=multi_id)
            written.append((msg, multi_id))
            if i % 5 == 0:
                w.write(BatteryStatusV0(timestamp=i))
                w.log(f"step {i}")
    return written


def test_iter_records_are_the_records_a_scan_finds_in_file_order(tmp_path: Path) -> None:
    path = tmp_path / "mixed.ulg"
    written = mixed_log(path)
    raw = path.read_bytes()
    found = [(o, m) for o, m, t in scan(raw) if t == "battery_status"]
    assert [m for _, m in found] == [m for _, m in written] and len(set(found)) == 40  # interleaved as logged
    for log in (_ulog.read(path), _ulog.read(path, index=False)):
        records = list(log.iter_records(BatteryStatus))
        assert [(r.offset, r.multi_id) for r in records] == found
        assert [r.instance for r in records] == [msg for msg, _ in written]
        assert {r.topic for r in records} == {"battery_status"} and all(isinstance(r, _ulog.Record) for r in records)
        assert [r.offset for r in log.iter_records(BatteryStatus, multi_id=1)] == [o for o, m in found if m == 1]
        v0 = list(log.iter_records(BatteryStatusV0))
        assert [(r.offset, r.multi_id, r.topic) for r in v0] == [x for x in scan(raw) if x[2] == "battery_status_v0"]
        assert [r.instance.timestamp for r in v0] == list(range(0, 40, 5))


def test_iter_records_keeps_defaults_for_what_the_log_lacks() -> None:
    last = data(0, BatteryStatus(timestamp=9, voltage_v=3.0, faults=5).encode()[:166])
    raw = battery_log(last).replace(b"uint16_t faults;", b"uint16_t faultz;")  # the 5 lands in faultz
    log = _ulog.read(raw, index=False)
    assert log.compare(BatteryStatus).missing == (("faults", "uint16_t"),)  # what was not decoded
    with pytest.raises(_ulog.ULogError, match="no format for topic 'nope' in this log"):
        log.iter_records(BatteryStatus, topic="nope")  # at the call, before any walk
    assert not log.walked
    *_, rec9 = log.iter_records(BatteryStatus)
    assert (rec9.instance.timestamp, rec9.instance.voltage_v, rec9.instance.faults) == (9, 3.0, 0)
    assert [r.topic for r in log.iter_records(BatteryStatusV0, topic=["battery_status"])] == ["battery_status"] * 4


def test_mmap_bytes_and_file_inputs_give_the_same_records(tmp_path: Path) -> None:
    path = tmp_path / "mixed.ulg"
    mixed_log(path)
    with path.open("rb") as f:
        inputs = [
            _ulog.read(path),
            _ulog.read(path, mmap=False),
            _ulog.read(path.read_bytes(), index=False),
            _ulog.read(f),
        ]
    assert isinstance(inputs[0].data, mmap.mmap) and isinstance(inputs[1].data, bytes)
    results = [list(log.iter_records(BatteryStatus)) for log in inputs]
    assert all(r == results[0] for r in results) and len(results[0]) == 40
    with _ulog.read(str(path)) as log:
        assert log.count("battery_status", 1) == len([m for m in results[0] if m.multi_id == 1])
    with pytest.raises(ValueError, match="closed"):
        log.messages(BatteryStatus)  # the map was released
    (tmp_path / "empty.ulg").write_bytes(b"")
    with pytest.raises(_ulog.ULogError, match="not a ULog file"):
        _ulog.read(tmp_path / "empty.ulg")  # nothing to map: read, and refused


def test_a_lazy_log_is_complete_once_walked(tmp_path: Path) -> None:
    path = tmp_path / "mixed.ulg"
    mixed_log(path)
    full, lazy = _ulog.read(path), _ulog.read(path, index=False)
    assert full.walked and full.indexed and not lazy.walked and lazy.subscriptions == [] and lazy.formats
    records = lazy.iter_records(BatteryStatus)
    first = next(records)
    del records  # abandoned: nothing of a half walk is kept
    assert not lazy.walked and lazy.logged == []
    again = list(lazy.iter_records(BatteryStatus))
    assert again[0] == first and len(again) == 40
    assert lazy.walked and not lazy.indexed and lazy.logged == full.logged and lazy.subscriptions == full.subscriptions
    assert lazy.topics() == full.topics() and lazy.count("battery_status", 1) == full.count("battery_status", 1)
    assert lazy.messages(BatteryStatus, multi_id=1) == full.messages(BatteryStatus, multi_id=1) and lazy.indexed
    assert _ulog.read(path, index=False).topics() == full.topics()  # counted by a walk that decodes nothing


def damaged_logs() -> dict[str, bytes]:
    sync = rec("S", _ulog.SYNC)
    body = rec("F", BATTERY_STATUS_FORMAT.encode()) + sub(0, 0, "battery_status")
    body += data(0, BatteryStatus(timestamp=1).encode()[:166])
    cut = data(0, BatteryStatus(timestamp=2).encode()[:166])[:50]
    start = len(head()) + len(body) + len(cut)
    appended = head(incompat=_ulog.INCOMPAT_DATA_APPENDED, offsets=(start,)) + body + cut
    return {
        "truncated": battery_log()[:-10],
        "resync": battery_log(b"\0\0\0garbage", sync, data(0, BatteryStatus(timestamp=7).encode()[:166])),
        "bad data": battery_log(data(9, b"x" * 8), data(0, bytes(100)), data(0, BatteryStatus(timestamp=5).encode())),
        "appended": appended + data(0, BatteryStatus(timestamp=3).encode()[:166]),
        "late format": battery_log(rec("F", b"late:uint8_t x;"), rec("I", b"\x0echar[1] late_1x")),
    }


STAMPS = {
    "truncated": [0, 1],
    "resync": [0, 1, 2, 7],
    "bad data": [0, 1, 2, 5],
    "appended": [1, 3],
    "late format": [0, 1, 2],
}


@pytest.mark.parametrize("name", list(STAMPS))
def test_walks_in_small_windows_agree_with_the_index(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    raw = damaged_logs()[name]
    full = _ulog.read(raw, warn=False)
    monkeypatch.setattr(_ulog, "_WINDOW", 7)  # a pause after nearly every record
    lazy = _ulog.read(raw, index=False, warn=False)
    records = list(lazy.iter_records(BatteryStatus))
    assert records == list(full.iter_records(BatteryStatus))
    assert [r.instance for r in records] == full.messages(BatteryStatus)
    assert [r.instance.timestamp for r in records] == STAMPS[name]
    assert all(raw[r.offset + 2] == ord("D") for r in records)
    assert bool(full.warnings) == (name != "late format")
    for attr in ("warnings", "skipped_records", "formats", "info", "subscriptions", "sync_count", "parameters"):
        assert getattr(lazy, attr) == getattr(full, attr), attr
    assert lazy.topics() == full.topics() and lazy.count("battery_status") == full.count("battery_status")


@pytest.mark.parametrize("name", ["sample_log_small.ulg", "sample_px4_events.ulg"])
def test_real_logs_walked_in_windows_read_as_indexed(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    path = REAL_LOGS / name
    if not path.is_file():
        missing("the shared real PX4 logs")
    full = _ulog.read(path)
    monkeypatch.setattr(_ulog, "_WINDOW", 4096)  # hundreds of windows, cutting between records of ~100 topics
    lazy = _ulog.read(path, index=False)
    records = list(lazy.iter_records(BatteryStatus))
    assert len(records) > 20 and records == list(full.iter_records(BatteryStatus))
    assert [r.instance for r in records if r.multi_id == 0] == full.messages(BatteryStatus)
    assert [r.offset for r in records] == sorted(r.offset for r in records)
    assert {r.multi_id for r in records} == {m for t, m in full.topics() if t == "battery_status"}
    for attr in ("info", "info_multiple", "parameters", "changed_parameters", "logged", "dropouts", "subscriptions"):
        assert getattr(lazy, attr) == getattr(full, attr), attr
    counts = {key: lazy.count(*key) for key in lazy.topics()}
    assert counts == {key: full.count(*key) for key in full.topics()} and len(counts) > 50


def test_streaming_memory_does_not_grow_with_the_log(tmp_path: Path) -> None:
    """A log 8x longer streams within the same memory: one window of offsets at a time."""
    peaks = []
    for n in (4_000, 32_000):
        path = tmp_path / f"long{n}.ulg"
        msg = BatteryStatus(voltage_v=12.0, remaining=0.5)
        with _ulog.Writer(path, messages=[BatteryStatus]) as w:
            for i in range(n):
                msg.timestamp = i
                w.write(msg, multi_id=i % 2)
        tracemalloc.start()
        try:
            with _ulog.read(path, index=False) as log:
                count = sum(1 for _ in log.iter_records(BatteryStatus))
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert count == n
        peaks.append(peak)
    # an index of 32,000 offsets alone takes over 1 MB; a list of instances ~30 MB
    assert peaks[1] < 400_000 and peaks[1] < peaks[0] * 1.25 + 20_000, peaks
