"""The generated MAVLink codec: error paths (each names the message, field and what was expected),
text robustness, frames, the stream parser and batch decoding."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from samples import mavlink_thing_xml as _xml

from codegen.frontends import mavlink
from generated import _mavlink as rt
from generated.mavlink import BatteryStatus


@pytest.fixture
def thing(tmp_path: Path, import_generated: Any) -> ModuleType:
    module: ModuleType = import_generated(mavlink.parse_file(_xml(tmp_path), root=tmp_path), "mavlink")
    return module


def test_payload_longer_than_max_length_is_a_decode_error() -> None:
    with pytest.raises(rt.DecodeError, match=r"BATTERY_STATUS: payload of 55 bytes exceeds the maximum length 54"):
        BatteryStatus.decode(bytes(55))


def test_short_payload_is_zero_filled_and_empty_encodes_to_one_byte() -> None:
    obj = BatteryStatus.decode(b"\x01")
    assert obj.current_consumed == 1 and obj.voltages == [0] * 10 and obj.fault_bitmask == 0
    zero = BatteryStatus.decode(b"")
    assert zero.encode() == b"\x00" and len(zero.encode(truncate=False)) == 54


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"temperature": 40000}, r"BATTERY_STATUS\.temperature: 40000 does not fit a signed 16-bit integer"),
        ({"id": -1}, r"BATTERY_STATUS\.id: -1 does not fit an unsigned 8-bit integer"),
        ({"fault_bitmask": 1.5}, r"BATTERY_STATUS\.fault_bitmask: expected an integer, got 1\.5"),
        ({"voltages": [1] * 9}, r"BATTERY_STATUS\.voltages: expected a list of 10 values"),
        ({"voltages": [1] * 9, "voltages_ext": [1] * 5}, r"BATTERY_STATUS\.voltages: expected a list of 10 values"),
        ({"voltages_ext": [0, 0, 0, 70000]}, r"BATTERY_STATUS\.voltages_ext\[3\]: 70000 does not fit an unsigned 16"),
    ],
)
def test_values_that_do_not_fit_name_the_field(changes: dict[str, Any], expected: str) -> None:
    obj = BatteryStatus(**changes)
    with pytest.raises(rt.EncodeError, match=expected):
        obj.encode()
    with pytest.raises(rt.EncodeError, match=expected):
        obj.encode_frame()


def test_text_bytes_and_wide_types(thing: ModuleType) -> None:
    cls = thing.Thing
    obj = cls(time_usec=2**64 - 1, label="abc", raw=b"\x01\x02\x03\x04", deltas=[-128, 0, 127], ratio=0.1,
              grade="A", extra=1.5)  # fmt: skip
    back = cls.decode(obj.encode())
    assert back == obj and cls.MSG_ID == 300 and len(obj.encode(truncate=False)) == cls.MAVLINK_MAX_LENGTH
    full = cls(label="12345678")  # exactly the capacity: no NUL terminator, as MAVLink allows
    assert cls.decode(full.encode()).label == "12345678"


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"label": "123456789"}, r"THING\.label: 9 bytes exceed the capacity 8"),
        ({"label": "ééééé"}, r"THING\.label: 10 bytes exceed the capacity 8"),
        ({"label": 5}, r"THING\.label: expected text, got 5"),
        ({"label": "\ud800"}, r"THING\.label: '\\ud800' cannot be encoded as UTF-8"),
        ({"raw": b"\x01"}, r"THING\.raw: expected 4 bytes"),
        ({"grade": "AB"}, r"THING\.grade: 2 bytes exceed the capacity 1"),
        ({"ratio": "x"}, r"THING\.ratio: expected a number, got 'x'"),
        ({"extra": 1e300}, r"THING\.extra: 1e\+300 does not fit a float"),
    ],
)
def test_text_and_bytes_errors_name_the_field(thing: ModuleType, changes: dict[str, Any], expected: str) -> None:
    with pytest.raises(thing.__dict__["_mav"].EncodeError, match=expected):
        thing.Thing(**changes).encode()


def test_invalid_utf8_text_decodes_losslessly(thing: ModuleType) -> None:
    # pymavlink decodes char[N] as ASCII with U+FFFD replacements; we never fail either, and keep the bytes
    cls = thing.Thing
    # wire order: the 8-byte fields, then the 1-byte ones in definition order, then the extension
    assert thing.__dict__["_THING_PAYLOAD"].format == "<Qd8s4s3b1sf"
    payload = cls().encode(truncate=False)
    start = 16
    bad = payload[:start] + b"\xff\xfeok\xc3\x00zz" + payload[start + 8 :]
    obj = cls.decode(bad)
    assert obj.label == "\udcff\udcfeok\udcc3"
    assert obj.encode(truncate=False) == bad.replace(b"\x00zz", b"\x00\x00\x00")
    assert cls.decode(cls(label="héllo").encode()).label == "héllo"


def test_mavlink1_needs_a_small_message_id(thing: ModuleType) -> None:
    with pytest.raises(thing.__dict__["_mav"].EncodeError, match="THING: message id 300 does not fit a MAVLink 1"):
        thing.Thing().encode_frame(mavlink1=True)


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        ({"seq": 256}, "seq: 256 does not fit 8 bits"),
        ({"sysid": -1}, "sysid: -1 does not fit 8 bits"),
        ({"compat_flags": 300}, "compat_flags: 300 does not fit 8 bits"),
        ({"incompat_flags": 1}, "incompat_flags: the signed flag 0x01 needs a signature"),
        ({"signature": b"123"}, "signature: expected 13 bytes, got 3"),
        ({"seq": 256, "mavlink1": True}, "seq: 256 does not fit 8 bits"),
        ({"compat_flags": 1, "mavlink1": True}, "mavlink1: MAVLink 1 frames carry no flags and no signature"),
        ({"signature": bytes(13), "mavlink1": True}, "mavlink1: MAVLink 1 frames carry no flags and no signature"),
    ],
)
def test_bad_frame_options(options: dict[str, Any], expected: str) -> None:
    with pytest.raises(rt.EncodeError, match=expected):
        BatteryStatus().encode_frame(**options)


FRAME = BatteryStatus(id=1, voltages=[3900] * 10).encode_frame(seq=3)


def _crc_fixed(frame: bytearray) -> bytes:
    extra = rt.REGISTRY.get(frame[7] | frame[8] << 8 | frame[9] << 16, (0,))[0]
    crc = rt.crc16(bytes(frame[1:-2]), extra)
    frame[-2:] = crc.to_bytes(2, "little")
    return bytes(frame)


@pytest.mark.parametrize(
    ("frame", "expected"),
    [
        (b"", "frame: no bytes"),
        (b"\x55" + FRAME[1:], "frame: expected magic 0xFD or 0xFE, got 0x55"),
        (FRAME[:8], "frame: 8 bytes are shorter than a MAVLink 2 frame"),
        (FRAME[:-1], r"frame: message id 147 needs \d+ bytes, got \d+"),
        (FRAME + b"\x00", "frame: 1 bytes follow the frame"),
        (FRAME[:-2] + b"\x00\x00", r"frame: bad CRC for message id 147 \(BATTERY_STATUS\): got 0x0000, expected"),
        (FRAME[:2] + b"\x02" + FRAME[3:], r"frame: unknown incompatibility flags 0x02"),
        (_crc_fixed(bytearray(FRAME[:7] + b"\x99\x99\x00" + FRAME[10:])), "message id 39321 is unknown"),
    ],
)
def test_parse_frame_rejects_bad_frames(frame: bytes, expected: str) -> None:
    with pytest.raises(rt.FrameError, match=expected):
        rt.parse_frame(frame)
    with pytest.raises(rt.FrameError, match=expected):
        rt.decode_message(frame)
    with pytest.raises(rt.FrameError, match=expected if "is unknown" not in expected else "holds message id 39321"):
        BatteryStatus.decode_frame(frame)


def test_frames_in_any_buffer_type() -> None:
    expected = BatteryStatus.decode_frame(FRAME)
    for buffer in (bytearray(FRAME), memoryview(FRAME)):
        assert BatteryStatus.decode_frame(buffer) == expected == rt.decode_message(buffer)
        assert rt.parse_frame(buffer).payload == rt.parse_frame(FRAME).payload
        assert BatteryStatus.decode(buffer[10:-2]) == expected


def test_decode_frame_of_another_message(thing: ModuleType) -> None:
    with pytest.raises(thing.__dict__["_mav"].FrameError, match="THING: frame holds message id 147, expected 300"):
        thing.Thing.decode_frame(FRAME)


def test_stream_parser_counters_and_strict_mode() -> None:
    unknown = _crc_fixed(bytearray(FRAME[:7] + b"\x99\x99\x00" + FRAME[10:]))
    bad = FRAME[:-1] + bytes([FRAME[-1] ^ 1])
    parser = rt.StreamParser()
    frames = parser.feed(b"junk" + unknown + bad + FRAME + FRAME[:5])
    assert [f.msgid for f in frames] == [147] and frames[0].seq == 3
    assert parser.frames == 1 and parser.bad_crc == 1 and parser.unknown_msgid == 1 and parser.pending == 5
    assert parser.skipped_bytes >= 4 + 2 and parser.last_error is not None
    assert parser.feed_messages(FRAME[5:]) == [BatteryStatus.decode_frame(FRAME)] and parser.pending == 0
    strict = rt.StreamParser(strict=True)
    with pytest.raises(rt.FrameError, match="bad CRC for message id 147"):
        strict.feed(bad)
    flags = rt.StreamParser()
    assert flags.feed(FRAME[:2] + b"\x04" + FRAME[3:]) == [] and flags.bad_flags == 1


def test_stream_parser_counts_payloads_too_long_for_the_message() -> None:
    long_payload = BatteryStatus().encode(truncate=False) + b"\x01"
    frame = rt.frame_v2(long_payload, 147, bytes([154]), 0, 1, 1)
    parser = rt.StreamParser()
    assert parser.feed_messages(frame) == [] and parser.decode_errors == 1
    assert parser.last_error is not None and "exceeds the maximum length 54" in parser.last_error


def test_decode_batch_both_paths_agree_and_reject_partial_records() -> None:
    objs = [BatteryStatus(id=i, voltages=[i] * 10, voltages_ext=[i, 0, 0, 1], current_consumed=-i) for i in range(5)]
    data = b"".join(o.encode(truncate=False) for o in objs)
    plain = BatteryStatus.decode_batch(data, use_numpy=False)
    assert plain["id"] == (0, 1, 2, 3, 4) and plain["voltages_ext"][2] == (2, 0, 0, 1)
    assert plain["current_consumed"] == (0, -1, -2, -3, -4)
    np_cols = BatteryStatus.decode_batch(data, use_numpy=True)
    for name, column in plain.items():
        assert [list(v) if isinstance(v, tuple) else v for v in column] == np_cols[name].tolist(), name
    assert BatteryStatus.decode_batch(b"", use_numpy=False)["voltages"] == []
    with pytest.raises(rt.DecodeError, match="BATTERY_STATUS: 55 bytes are not a whole number of 54-byte records"):
        BatteryStatus.decode_batch(bytes(55), use_numpy=False)
    with pytest.raises(rt.DecodeError, match="54-byte records"):
        BatteryStatus.decode_batch(bytes(55), use_numpy=True)


def test_text_columns_in_batches(thing: ModuleType) -> None:
    cls = thing.Thing
    data = cls(label="ab").encode(truncate=False) + cls(label="cd", grade="z").encode(truncate=False)
    cols = cls.decode_batch(data, use_numpy=False)
    assert cols["label"] == ["ab", "cd"] and cols["grade"] == ["", "z"] and cols["raw"] == (bytes(4), bytes(4))


def test_field_named_like_a_codec_member_is_renamed(tmp_path: Path, import_generated: Any) -> None:
    schema = mavlink.parse_file(_xml(tmp_path, '<field type="uint8_t" name="MSG_ID">x</field>\n'), root=tmp_path)
    cls = import_generated(schema, "mavlink").Thing
    assert cls.MSG_ID == 300  # the codec's constant keeps its name
    value = cls(MSG_ID_=7)
    assert cls.decode(value.encode()).MSG_ID_ == 7 and value.to_dict() == {"MSG_ID": 7}
