"""PX4's battery_info topic (uorb.BatteryInfo) converts to and from MAVLink's BATTERY_INFO through
the shared concepts: the pack id (1-based in PX4, 0 unassigned; 0-based in MAVLink, as PX4's
BATTERY_STATUS stream writes ``id - 1``) and the serial number as text (all bytes zero: unknown)."""

from __future__ import annotations

from generated.convert import LossReport
from generated.convert.uorb_info_mavlink_info import mavlink_info_to_uorb_info, uorb_info_to_mavlink_info
from generated.convert.uorb_uorb_info import uorb_to_uorb_info
from generated.uorb import BatteryInfo, BatteryStatus


def test_id_and_serial_number_reach_battery_info() -> None:
    report = LossReport()
    mav = uorb_info_to_mavlink_info(BatteryInfo(timestamp=5, id=2, serial_number="SN-0042"), report=report)
    assert (mav.id, mav.serial_number) == (1, "SN-0042")
    assert "mavlink.BATTERY_INFO.serial_number" not in {e.field for e in report.entries}
    back = mavlink_info_to_uorb_info(mav)
    assert (back.id, back.serial_number) == (2, "SN-0042")


def test_an_empty_serial_number_is_unknown() -> None:
    info = BatteryInfo(id=1)
    assert info.serial_number == "" and info.validate() == []  # [@invalid 0 All bytes]: the default
    report = LossReport()
    mav = uorb_info_to_mavlink_info(info, report=report)
    assert mav.serial_number == ""
    assert ("unknown", "mavlink.BATTERY_INFO.serial_number") in {(e.kind, e.field) for e in report.entries}


def test_battery_info_decodes_as_px4_lays_it_out() -> None:
    info = BatteryInfo(timestamp=7, id=3, serial_number="ABC")
    raw = info.encode()
    # PX4's order: timestamp, then the 1-byte elements as written (id, serial_number), 7 bytes of padding
    assert len(raw) == 48 and raw[8] == 3 and raw[9:12] == b"ABC" and raw[12:] == bytes(36)
    assert BatteryInfo.decode(raw) == info


def test_battery_status_ids_match_battery_info_ids() -> None:
    info = uorb_to_uorb_info(BatteryStatus(id=4))
    assert info.id == 4 and info.serial_number == ""
