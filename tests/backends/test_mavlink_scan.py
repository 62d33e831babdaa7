"""The fast walk over whole MAVLink streams (``_mavlink.scan_frames``, under the stream parser and the .tlog
reader): exactly the frames ``parse_frame`` gives for the same bytes, and a stop at the first entry that is
not a good frame, for the caller to judge."""

from __future__ import annotations

import pytest

from generated import _mavlink as rt
from generated.mavlink import BatteryInfo, BatteryStatus, Heartbeat

GOOD = [
    # trailing zeros dropped from the payload (MAVLink 2 truncation)
    BatteryStatus(id=1, voltages=[3900] * 10).encode_frame(seq=1),
    # the whole 54-byte payload, a compatibility flag (0x80), other ids
    BatteryStatus(id=2, voltages=[3900] * 10, fault_bitmask=7).encode_frame(seq=2, sysid=7, compid=9, compat_flags=128),
    # signed: the 13 signature bytes follow the CRC
    BatteryStatus(id=3, current_consumed=-5).encode_frame(seq=3, signature=bytes(range(1, 14))),
    BatteryStatus(id=4, temperature=-300).encode_frame(seq=4, mavlink1=True),
    Heartbeat(type=2, autopilot=3).encode_frame(seq=5),
    Heartbeat(type=2).encode_frame(seq=6, mavlink1=True),
    BatteryInfo(id=1).encode_frame(seq=7),  # an id past 255
]


def _entries(frames: list[bytes], gap: int) -> tuple[bytes, list[int]]:
    """The frames each after ``gap`` bytes of its own (a .tlog's timestamps), and the entries' offsets."""
    data, offsets = b"", []
    for k, frame in enumerate(frames):
        offsets.append(len(data))
        data += (1_700_000_000_000_000 + k).to_bytes(8, "big")[8 - gap :] + frame
    return data, offsets


@pytest.mark.parametrize("gap", [0, 8])
def test_scan_gives_the_frames_parse_frame_gives(gap: int) -> None:
    data, offsets = _entries(GOOD, gap)
    expected = [rt.parse_frame(f) for f in GOOD]
    assert {f.version for f in expected} == {1, 2} and expected[2].signature == bytes(range(1, 14))
    assert rt.scan_frames(data, 0, len(data), gap=gap) == (expected, offsets, 0, len(data))
    wanted = [i for i, f in enumerate(expected) if f.msgid == 147]
    frames, found, others, stop = rt.scan_frames(data, 0, len(data), gap=gap, wanted={147})
    assert frames == [expected[i] for i in wanted] and found == [offsets[i] for i in wanted]
    assert others == len(GOOD) - len(wanted) and stop == len(data)
    assert rt.scan_frames(data, offsets[3], offsets[5], gap=gap) == (expected[3:5], offsets[3:5], 0, offsets[5])


def _unknown_id(frame: bytes) -> bytes:
    out = bytearray(frame[:7] + b"\x99\x99\x00" + frame[10:])
    out[-2:] = rt.crc16(bytes(out[1:-2]), 0).to_bytes(2, "little")
    return bytes(out)


FRAME = GOOD[0]
DAMAGED = {
    "bad CRC": FRAME[:-1] + bytes([FRAME[-1] ^ 1]),
    "bad CRC, MAVLink 1": GOOD[3][:-1] + bytes([GOOD[3][-1] ^ 1]),
    "garbage": b"\x55" + FRAME[1:],
    "unknown id": _unknown_id(FRAME),
    "unknown incompat flag": FRAME[:2] + b"\x02" + FRAME[3:],
    "cut off": FRAME[:-1],
    "header cut off": FRAME[:9],
}


@pytest.mark.parametrize("damage", DAMAGED)
@pytest.mark.parametrize("gap", [0, 8])
def test_scan_stops_where_parse_frame_rejects(damage: str, gap: int) -> None:
    bad = DAMAGED[damage]
    with pytest.raises(rt.FrameError):
        rt.parse_frame(bad)
    frames = [GOOD[1], bad, GOOD[4]] if damage not in ("cut off", "header cut off") else [GOOD[1], bad]
    data, offsets = _entries(frames, gap)
    assert rt.scan_frames(data, 0, len(data), gap=gap) == ([rt.parse_frame(GOOD[1])], offsets[:1], 0, offsets[1])


def test_stream_parser_fed_whole_or_byte_by_byte() -> None:
    stream = b"".join(GOOD[:3]) + b"junk" + DAMAGED["bad CRC"] + b"".join(GOOD[3:]) + DAMAGED["unknown id"] + GOOD[0]
    expected = [rt.parse_frame(f) for f in [*GOOD, GOOD[0]]]
    whole, pieces = rt.StreamParser(), rt.StreamParser()
    assert whole.feed(stream) == expected
    assert [f for i in range(len(stream)) for f in pieces.feed(stream[i : i + 1])] == expected
    for parser in (whole, pieces):
        assert (parser.frames, parser.bad_crc, parser.unknown_msgid, parser.pending) == (len(expected), 1, 1, 0)
    assert whole.skipped_bytes == pieces.skipped_bytes
