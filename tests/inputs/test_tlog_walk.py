"""The .tlog reader's walk: runs of good frames go through the runtime's fast walk (``scan_frames``), the
entries that stop it (damage, the log's first frame) through the judged path; the records are exactly those
of decoding each good frame on its own, with their offsets, stamps and numbers, from bytes or a mapped file."""

from __future__ import annotations

import io
from pathlib import Path

from codegen.inputs.tlog import FrameRecord, StreamStats, read_frames
from generated import _mavlink as rt
from generated.mavlink import BatteryStatus, Heartbeat

START = 1_700_000_000_000_000


def _battery(k: int, **frame: object) -> bytes:
    return BatteryStatus(id=k % 3, voltages=[3900 + k] * 10, current_consumed=k).encode_frame(seq=k % 256, **frame)  # type: ignore[arg-type]


def _log() -> tuple[bytes, list[FrameRecord], int]:
    """A log with damage among good frames; the records expected of it; the stamp of its first good frame."""
    data = b""
    expected: list[FrameRecord] = []
    first = START + 1
    for k in range(300):
        stamp = START + k if k else 1 << 63  # a damaged stamp first: the log starts at the next frame
        if k % 50 == 7:
            frame = _battery(k)[:-1] + b"\x00"  # bad CRC: skipped, counted
        elif k % 50 == 11:
            data += b"\x55" * 5  # garbage before an entry
            frame = _battery(k)
        elif k % 4 == 1:
            frame = Heartbeat(type=2).encode_frame(seq=k % 256, mavlink1=k % 8 == 1)
        else:
            frame = _battery(k, signature=bytes(13)) if k % 10 == 3 else _battery(k, mavlink1=k % 10 == 5)
        offset = len(data)
        data += stamp.to_bytes(8, "big") + frame
        if k % 50 != 7 and frame[7 if frame[0] == 0xFD else 5] == 147:
            parsed = rt.parse_frame(frame)
            expected.append(FrameRecord(len(expected), offset, stamp, parsed, BatteryStatus.decode(parsed.payload)))
    return data, expected, first


def test_records_are_those_of_each_frame_decoded_alone(tmp_path: Path) -> None:
    data, expected, first = _log()
    path = tmp_path / "damaged.tlog"
    path.write_bytes(data)
    for source in (io.BytesIO(data), path):  # bytes, and the file memory-mapped
        stats = StreamStats()
        assert list(read_frames(source, "damaged.tlog", BatteryStatus, stats, timestamps=True)) == expected
        assert (stats.records, stats.bad_crc, stats.garbage_bytes) == (len(expected), 6, 30)
        assert stats.other_frames == sum(1 for k in range(300) if k % 4 == 1 and k % 50 not in (7, 11))
        assert stats.first_stamp == first
    assert {r.frame.version for r in expected} == {1, 2} and any(r.frame.signature for r in expected)
