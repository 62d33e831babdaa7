"""A .tlog with stray magic bytes: no real frame is swallowed (issue 10, item 7).

The log is built with pymavlink (2,000 BATTERY_STATUS frames between HEARTBEAT and SYS_STATUS frames, a
message this package does not generate) and pymavlink counts and decodes the clean stream; then stray
entries are inserted whose fake header claims just the length that would jump over the next real frame,
plus random garbage. The .tlog reader and the generated stream parser must still find every frame
pymavlink found, with the same values.
"""

from __future__ import annotations

import random
import struct
from pathlib import Path

from pymavlink.dialects.v20 import common as mavlink2

from codegen.inputs.tlog import StreamStats, read_frames
from generated import _mavlink as rt
from generated.mavlink import BatteryStatus

COUNT = 2000


def _pymavlink_log() -> list[tuple[bytes, bool]]:
    """Frames packed by pymavlink, each with whether it is a BATTERY_STATUS."""
    mav = mavlink2.MAVLink(None, srcSystem=1, srcComponent=1)
    rng = random.Random(10)
    out: list[tuple[bytes, bool]] = []
    for i in range(COUNT):
        out.append((mav.heartbeat_encode(6, 8, 0, 0, 4).pack(mav), False))
        if i % 3 == 0:
            sys_status = mav.sys_status_encode(0, 0, 0, 500, 11800, -1, -1, 0, 0, 0, 0, 0, 0)
            out.append((sys_status.pack(mav), False))
        volts = [rng.randrange(3000, 4300) for _ in range(4)] + [65535] * 6
        battery = mav.battery_status_encode(i % 256, 1, 1, 2500, volts, rng.randrange(0, 3000), i, -1, 50)
        out.append((battery.pack(mav), True))
    return out


def _damaged_tlog(frames: list[tuple[bytes, bool]]) -> tuple[bytes, bytes]:
    """The .tlog with stray entries before some battery frames, and the raw stream with the same damage."""
    rng = random.Random(7)
    tlog, raw = bytearray(), bytearray()
    for k, (frame, wanted) in enumerate(frames):
        junk = b""
        if wanted and k + 1 < len(frames) and k % 7 == 2:
            # a fake MAVLink 2 header of id 42 whose length lands exactly on the next entry: plausible,
            # and without a CRC check it would swallow this battery frame
            length = len(frame) + 8 - 2  # 8 + 10 + (12 + length) == 18 + 8 + len(frame)
            junk = bytes(8) + struct.pack("<BBBBBBBHB", 0xFD, length, 0, 0, 0, 1, 1, 42, 0)
        elif k % 11 == 5:
            junk = bytes(rng.choice((0xFD, 0xFE, 0x00, 0x55)) for _ in range(rng.randrange(1, 30)))
        stamp = struct.pack(">Q", 1_700_000_000_000_000 + 10_000 * k)
        tlog += junk + stamp + frame
        raw += junk + frame
    return bytes(tlog), bytes(raw)


def test_tlog_reader_finds_every_frame_pymavlink_finds(tmp_path: Path) -> None:
    frames = _pymavlink_log()
    parser = mavlink2.MAVLink(None)
    parser.robust_parsing = True
    theirs = [m for m in parser.parse_buffer(b"".join(f for f, _ in frames)) or [] if m.get_type() == "BATTERY_STATUS"]
    assert len(theirs) == COUNT
    tlog, raw = _damaged_tlog(frames)
    path = tmp_path / "damaged.tlog"
    path.write_bytes(tlog)
    stats = StreamStats()
    ours = [r.instance for r in read_frames(path, "damaged.tlog", BatteryStatus, stats, timestamps=True)]
    assert len(ours) == len(theirs) == stats.records
    for mine, their in zip(ours, theirs, strict=True):
        assert isinstance(mine, BatteryStatus)
        assert (mine.id, mine.current_consumed, mine.current_battery) == (
            their.id,
            their.current_consumed,
            their.current_battery,
        )
        assert list(mine.voltages) == list(their.voltages)
    assert stats.garbage_bytes > 0 and stats.bad_crc == 0
    # the generated stream parser, on the same damage without timestamps, agrees
    stream = rt.StreamParser()
    found = [f for f in stream.feed(raw) if f.msgid == BatteryStatus.MSG_ID]
    assert len(found) == COUNT


def test_strict_stream_parser_raises_once_and_counts_each_frame_once() -> None:
    good = [BatteryStatus(id=i).encode_frame(seq=i, sysid=1, compid=1) for i in range(3)]
    bad = bytearray(BatteryStatus(id=9).encode_frame(seq=9, sysid=1, compid=1))
    bad[-1] ^= 0xFF
    assert 0xFD not in bad[1:] and 0xFE not in bad[1:]  # one rejection, not one per stray magic inside
    parser = rt.StreamParser(strict=True)
    errors = 0
    got: list[int] = []
    for chunk in (good[0] + bytes(bad) + good[1], b"", good[2]):
        try:
            got += [f.seq for f in parser.feed(chunk)]
        except rt.FrameError as exc:
            errors += 1
            assert "bad CRC" in str(exc)
    assert (errors, got, parser.frames, parser.bad_crc, parser.pending) == (1, [0, 1, 2], 3, 1, 0)
    # feed_messages: the message decoded before a payload too long for the class comes with the next call
    long = rt.frame_v2(BatteryStatus().encode(truncate=False) + b"\x01", 147, bytes([154]), 0, 1, 1)
    parser = rt.StreamParser(strict=True)
    try:
        parser.feed_messages(good[0] + long + good[1])
    except rt.FrameError as exc:
        assert "exceeds the maximum length 54" in str(exc)
    else:
        raise AssertionError("no FrameError")
    assert [m.id for m in parser.feed_messages(b"")] == [0, 1] and parser.decode_errors == 1
