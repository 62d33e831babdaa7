"""Our .tlog reading against pymavlink's: a log of pymavlink-packed frames (MAVLink 1 and 2,
BATTERY_STATUS among other messages, one frame corrupted) read back by mavutil and by us."""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path
from typing import Any

import pytest
from pymavlink import mavutil
from pymavlink.dialects.v10 import common as v10
from pymavlink.dialects.v20 import common as v20

from codegen.cli.main import main
from codegen.inputs.tlog import StreamStats, read_frames
from generated.mavlink import BatteryStatus

T0 = 1_700_000_000_000_000  # microseconds since the Unix epoch


def _battery(i: int, mav: Any, module: Any = v20) -> bytes:
    msg = module.MAVLink_battery_status_message(
        i % 3, 0, 1, 2500 + i, [4000 + i, 4001, 65535, 65535, 65535, 65535, 65535, 65535, 65535, 65535],
        100 * i, 1000 + i, 2000, 50 - i, *(() if module is v10 else (60 * i, 1, [0, 0, 0, 0], 0, 1 << (i % 5))),
    )  # fmt: skip
    frame: bytes = msg.pack(mav)
    return frame


def _write_tlog(path: Path) -> int:
    mav2 = v20.MAVLink(None, srcSystem=1, srcComponent=1)
    mav1 = v10.MAVLink(None, srcSystem=7, srcComponent=9)
    frames: list[bytes] = []
    for i in range(30):
        frames.append(v20.MAVLink_heartbeat_message(2, 3, 0, 0, 4, 3).pack(mav2))
        frames.append(v20.MAVLink_attitude_message(i, 0.1, -0.2, 0.3, 0.0, 0.0, 0.0).pack(mav2))
        frames.append(_battery(i, mav1, v10) if i % 7 == 0 else _battery(i, mav2))
    bad = bytearray(frames[3 * 11 + 2])  # one BATTERY_STATUS frame with a flipped payload byte
    bad[14] ^= 0x5A
    frames[3 * 11 + 2] = bytes(bad)
    path.write_bytes(b"".join(struct.pack(">Q", T0 + 1000 * n) + f for n, f in enumerate(frames)))
    return len(frames)


def _pymavlink_records(path: Path, monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    monkeypatch.setenv("MAVLINK20", "1")  # mavutil picks its MAVLink 2 parser only in this mode
    conn = mavutil.mavlink_connection(str(path), dialect="common")
    out: list[Any] = []
    while True:
        msg = conn.recv_match(type="BATTERY_STATUS")
        if msg is None:
            return out
        out.append(msg)


def _same(ours: Any, theirs: Any) -> bool:
    if isinstance(ours, float) and isinstance(theirs, float) and math.isnan(ours):
        return math.isnan(theirs)
    if isinstance(ours, list | tuple) or isinstance(theirs, list | tuple):
        return list(ours) == list(theirs)
    return bool(ours == theirs)


@pytest.fixture
def tlog(tmp_path: Path) -> Path:
    path = tmp_path / "flight.tlog"
    _write_tlog(path)
    return path


def test_we_read_exactly_the_records_pymavlink_reads(tlog: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    theirs = _pymavlink_records(tlog, monkeypatch)
    stats = StreamStats()
    ours = list(read_frames(tlog, "flight.tlog", BatteryStatus, stats, timestamps=True))
    assert len(theirs) == 29 and len(ours) == len(theirs)  # 30 written, one corrupted
    for mine, pm in zip(ours, theirs, strict=True):
        assert mine.timestamp is not None and mine.timestamp * 1e-6 == pytest.approx(pm._timestamp, abs=1e-6)
        assert (mine.frame.sysid, mine.frame.compid, mine.frame.seq) == (
            pm.get_srcSystem(), pm.get_srcComponent(), pm.get_seq()
        )  # fmt: skip
        for name, value in mine.instance.to_dict().items():
            assert _same(value, getattr(pm, name)), (name, value, getattr(pm, name))
    assert (stats.records, stats.bad_crc, stats.other_frames, stats.garbage_bytes) == (29, 1, 60, 0)


def test_validate_reports_the_same_records_and_the_damage(
    tlog: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    theirs = _pymavlink_records(tlog, monkeypatch)
    code = main(["validate", "--format", "json", str(tlog)])  # --message defaults to mavlink.BATTERY_STATUS
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["message"] == "mavlink.BATTERY_STATUS"
    [report] = doc["files"]
    assert report["records"] == len(theirs)
    [notice] = report["notices"]
    assert notice["severity"] == "warning" and notice["data"]["bad_crc"] == 1
