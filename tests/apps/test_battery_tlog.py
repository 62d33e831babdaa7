"""The tlog battery source (codegen/apps/battery/tlog_batches.py) on tlogs packed by pymavlink: the arming rule
(the vehicle's HEARTBEAT of the battery's own system; a ground station's ignored), the SYS_STATUS fallback
(battery 0 only where a system sends no BATTERY_STATUS), and the clock (t since the log's first frame)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
from pymavlink.dialects.v20 import common

from codegen.apps.battery.view import read_view

T0 = 1_700_000_000_000_000


def _entry(t: float, msg: object, mav: common.MAVLink) -> bytes:
    return struct.pack(">Q", T0 + round(t * 1e6)) + msg.pack(mav)  # type: ignore[attr-defined]


def _hb(armed: bool, kind: int = common.MAV_TYPE_QUADROTOR, autopilot: int = common.MAV_AUTOPILOT_ARDUPILOTMEGA):
    return common.MAVLink_heartbeat_message(kind, autopilot, 128 if armed else 0, 0, 4, 3)


def _sys_status(mv: int) -> object:
    return common.MAVLink_sys_status_message(0, 0, 0, 500, mv, 1250, 60, 0, 0, 0, 0, 0, 0)


def _battery(i: int, mv: int) -> object:
    return common.MAVLink_battery_status_message(i, 0, 1, 2500, [mv] + [65535] * 9, 800, 100, 200, 70)


@pytest.fixture
def mav() -> tuple[common.MAVLink, common.MAVLink, common.MAVLink]:
    return (
        common.MAVLink(None, srcSystem=1, srcComponent=1),
        common.MAVLink(None, srcSystem=255, srcComponent=190),
        common.MAVLink(None, srcSystem=2, srcComponent=1),
    )


def test_sys_status_is_battery_0_armed_from_the_vehicles_heartbeat(tmp_path: Path, mav: tuple) -> None:
    v, gcs, _ = mav
    out = _entry(0.0, _hb(True, common.MAV_TYPE_GCS, common.MAV_AUTOPILOT_INVALID), gcs)  # the log's first frame
    for i in range(10):
        t = 1.0 + i
        if i in (2, 6):
            out += _entry(t, _hb(i == 2), v)  # armed at t = 3, disarmed at t = 7
        out += _entry(t, _hb(True, common.MAV_TYPE_GCS, common.MAV_AUTOPILOT_INVALID), gcs)  # not the vehicle
        out += _entry(t, _sys_status(12000 - 100 * i), v)
    path = tmp_path / "sys.tlog"
    path.write_bytes(out)
    [chunk] = list(read_view(path))
    batch = chunk.batch
    assert batch.message == "mavlink.SYS_STATUS" and batch.vehicle == "mavlink:1"
    assert batch.vehicle_type == common.MAV_TYPE_QUADROTOR
    assert chunk.battery.tolist() == [0] * 10
    assert batch.t.tolist() == [1.0 + i for i in range(10)]  # from the GCS heartbeat at t = 0
    assert batch.origin_us == T0 and batch.utc_offset_us == 0
    armed = batch.armed
    assert armed is not None
    assert np.isnan(armed[:2]).all() and armed[2:6].tolist() == [1.0] * 4 and armed[6:].tolist() == [0.0] * 4
    assert chunk.number("pack_voltage")[0] == pytest.approx(12.0)
    assert chunk.number("current")[0] == pytest.approx(12.5)
    assert chunk.number("state_of_charge")[0] == pytest.approx(0.6)


def test_battery_status_wins_and_each_system_has_its_own_arming(tmp_path: Path, mav: tuple) -> None:
    v, _, other = mav
    out = b""
    for i in range(6):
        t = float(i)
        out += _entry(t, _hb(True), v) + _entry(t, _hb(False, common.MAV_TYPE_GROUND_ROVER), other)
        out += _entry(t, _sys_status(11000), v) + _entry(t, _battery(i % 2, 15000 + i), v)
        out += _entry(t, _sys_status(9000), other)  # system 2 sends no BATTERY_STATUS
    path = tmp_path / "two.tlog"
    path.write_bytes(out)
    chunks = list(read_view(path))
    got = {(c.batch.vehicle, c.batch.message, int(c.battery[0])): c for c in chunks}
    assert sorted(got) == [
        ("mavlink:1", "mavlink.BATTERY_STATUS", 0),
        ("mavlink:1", "mavlink.BATTERY_STATUS", 1),
        ("mavlink:2", "mavlink.SYS_STATUS", 0),
    ]
    one = got[("mavlink:1", "mavlink.BATTERY_STATUS", 1)]
    assert one.batch.t.tolist() == [1.0, 3.0, 5.0] and one.number("pack_voltage").tolist() == [15.001, 15.003, 15.005]
    assert one.batch.armed is not None and one.batch.armed.tolist() == [1.0] * 3
    rover = got[("mavlink:2", "mavlink.SYS_STATUS", 0)]
    assert rover.batch.armed is not None and rover.batch.armed.tolist() == [0.0] * 6
    assert rover.batch.vehicle_type == common.MAV_TYPE_GROUND_ROVER


def test_a_system_without_a_vehicle_heartbeat_has_no_arming_state(tmp_path: Path, mav: tuple) -> None:
    v, _, _ = mav
    path = tmp_path / "quiet.tlog"
    path.write_bytes(b"".join(_entry(float(i), _sys_status(12000), v) for i in range(3)))
    [chunk] = list(read_view(path))
    assert chunk.batch.armed is None and chunk.batch.vehicle_type is None
