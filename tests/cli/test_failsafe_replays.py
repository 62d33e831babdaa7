"""``battgen failsafe`` on flight logs: a DataFlash .bin (written from the format's FMT records), a
MAVLink .tlog (frames packed by pymavlink) and the equivalent JSON Lines stream give the same
events; real PX4 .ulg logs are read as pyulog reads them."""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

import pytest

from codegen.apps.failsafe.logs import log_samples
from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from dataflash_writer import battery_log
from shared_data import REAL_LOGS

# a rover (CRUISE_SPEED is Rover's) with two packs: battery 1 by voltage, battery 2 by capacity
PARAMS = {
    "CRUISE_SPEED": 2.0,
    "BATT_LOW_VOLT": 10.5,
    "BATT_CRT_VOLT": 10.0,
    "BATT_LOW_TIMER": 5,
    "BATT_FS_LOW_ACT": 2,  # Hold
    "BATT_FS_CRT_ACT": 1,  # RTL: below Hold on Rover's list, so announced but not run
    "BATT2_CAPACITY": 2000,
    "BATT2_LOW_MAH": 500,
    "BATT2_FS_LOW_ACT": 5,  # Terminate: outranks everything
}
ARM_AT, DISARM_AT = 1.0, 59.0


def flight() -> list[tuple[float, int, float, float, float]]:
    """(t, instance 0-based, volts, amps, mAh used) at 5 Hz for a minute."""
    rows = []
    for i in range(300):
        t = i / 5
        volts = 12.0 if t < 10 else 10.4 if t < 30 else 9.9
        rows.append((t, 0, volts, 8.0, round(t * 8 / 3.6, 1)))
        rows.append((t, 1, 12.2, 120.0, round(t * 120 / 3.6)))
    return rows


def armed_at(t: float) -> bool:
    return ARM_AT <= t < DISARM_AT


def write_jsonl(path: Path) -> Path:
    lines = []
    for t, inst, volts, amps, used in flight():
        battery = {"voltage_v": volts, "current_a": amps, "consumed_mah": used}
        lines.append(json.dumps({"t": t, "armed": armed_at(t), "instance": inst + 1, "battery": battery}))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def write_bin(path: Path) -> Path:
    return battery_log(path, PARAMS, flight(), [(ARM_AT, True), (DISARM_AT, False)])


def write_tlog(path: Path, *, parameters: bool = False) -> Path:
    """The flight as a tlog; with ``parameters``, a ground station's parameter download first (PARAM_VALUE frames,
    ArduPilot's encoding: the number itself)."""
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    epoch = 1_700_000_000_000_000
    out = bytearray()
    if parameters:
        for k, (name, value) in enumerate(PARAMS.items()):
            msg = mav.param_value_encode(name.encode(), float(value), common.MAV_PARAM_TYPE_REAL32, len(PARAMS), k)
            out += struct.pack(">Q", epoch) + msg.pack(mav)
    last_second = -1
    for t, inst, volts, amps, used in flight():
        stamp = struct.pack(">Q", epoch + round(t * 1e6))
        if int(t) != last_second or t == ARM_AT:  # 1 Hz heartbeats, and one right at arming
            last_second = int(t)
            base_mode = common.MAV_MODE_FLAG_SAFETY_ARMED if armed_at(t) else 0
            hb = mav.heartbeat_encode(common.MAV_TYPE_GROUND_ROVER, common.MAV_AUTOPILOT_ARDUPILOTMEGA, base_mode, 0, 4)
            out += stamp + hb.pack(mav)
        cells = [round(volts * 1000)] + [65535] * 9
        msg = mav.battery_status_encode(inst, 0, 0, 32767, cells, round(amps * 100), round(used), -1, -1)
        out += stamp + msg.pack(mav)
    path.write_bytes(bytes(out))
    return path


def events(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[list[dict[str, object]], str]:
    assert main(["failsafe", "--json", *args]) == 0
    captured = capsys.readouterr()
    return [json.loads(line) for line in captured.out.splitlines()], captured.err


KEYS = ("t", "battery", "level", "cause", "value", "threshold", "action", "action_code", "executed", "outcome")


def comparable(found: list[dict[str, object]]) -> list[tuple[object, ...]]:
    return [(*(e[k] for k in KEYS), e["ardupilot_text"], e["seed_text"]) for e in found]


def test_bin_tlog_and_jsonl_give_the_same_events(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    params = tmp_path / "rover.param"
    params.write_text("".join(f"{k},{v}\n" for k, v in PARAMS.items()), encoding="utf-8")
    jsonl, err = events(capsys, "--params", str(params), str(write_jsonl(tmp_path / "flight.jsonl")))
    assert "vehicle rover (detected from CRUISE_SPEED" in err
    expected = comparable(jsonl)
    # battery 1: below 10.5 V from t = 10 -> LOW after > 5 s; below 10.0 V from t = 30 -> CRITICAL
    # battery 2: 2000 - used < 500 mAh once used > 1500 mAh: at 120 A, after t = 45 s
    assert [(e[0], e[1], e[2], e[8], e[9]) for e in expected] == [
        (15.2, 1, "LOW", True, "hold"),
        (35.2, 1, "CRITICAL", False, "not run"),
        (45.2, 2, "LOW", True, "disarm"),
    ]
    assert expected[0][-2] == "Battery 1 is low 10.40V used 34 mAh"
    assert expected[2][-2] == "Battery 2 is low 12.20V used 1507 mAh"
    bin_params, _ = events(capsys, "--params", str(params), str(write_bin(tmp_path / "flight.bin")))
    bin_own, err = events(capsys, str(tmp_path / "flight.bin"))  # the log's PARM records
    assert "parameters from" in err and "(PARM records)" in err and "detected from CRUISE_SPEED" in err
    tlog, _ = events(capsys, "--params", str(params), str(write_tlog(tmp_path / "flight.tlog")))
    assert comparable(bin_params) == expected
    assert comparable(bin_own) == expected
    assert comparable(tlog) == expected
    # the battery view's record of the event: message, record number among the battery's, battery
    assert bin_params[0]["where"] == "dataflash.BAT record 76 of battery 0"
    assert tlog[0]["where"].startswith("mavlink.BATTERY_STATUS record ")


def test_tlog_without_battery_status_uses_sys_status(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    out = bytearray()
    for i in range(40):
        stamp = struct.pack(">Q", 1_700_000_000_000_000 + i * 1_000_000)
        hb = mav.heartbeat_encode(common.MAV_TYPE_QUADROTOR, common.MAV_AUTOPILOT_ARDUPILOTMEGA, 128, 0, 4)
        gcs = mav.heartbeat_encode(common.MAV_TYPE_GCS, common.MAV_AUTOPILOT_INVALID, 0, 0, 0)  # not the vehicle
        sys_status = mav.sys_status_encode(0, 0, 0, 500, 10400 if i >= 5 else 12000, 500, 50, 0, 0, 0, 0, 0, 0)
        out += stamp + hb.pack(mav) + stamp + gcs.pack(mav) + stamp + sys_status.pack(mav)
    path = tmp_path / "copter.tlog"
    path.write_bytes(bytes(out))
    params = tmp_path / "c.param"
    params.write_text("RTL_ALT,1500\n", encoding="utf-8")  # Copter: BATT_LOW_VOLT defaults to 10.5 V
    # no BATT*_ parameter at all: exit 1 unless asked for (defaults alone are then the point)
    assert main(["failsafe", "--params", str(params), str(path)]) == 1
    assert "no BATT*_ parameter (1 parameters read)" in capsys.readouterr().err
    found, err = events(capsys, "--allow-empty", "--params", str(params), str(path))
    assert "vehicle copter (detected from RTL_ALT" in err
    assert [(e["t"], e["battery"], e["level"], e["action"]) for e in found] == [(16.0, 1, "LOW", "None")]


@pytest.mark.skipif(not REAL_LOGS.is_dir(), reason="real PX4 logs not present")
@pytest.mark.parametrize("name", ["sample_log_small.ulg", "sample_px4_events.ulg"])
def test_real_ulog_samples_match_pyulog(name: str) -> None:
    from pyulog import ULog

    log = ULog(str(REAL_LOGS / name), ["battery_status", "vehicle_status"])
    data = {d.name: d.data for d in log.data_list if d.multi_id == 0}
    bat, status = data["battery_status"], data["vehicle_status"]
    everything = list(log_samples(REAL_LOGS / name).samples())
    ours = [s for s in everything if s.instance == 1]  # multi_id 0
    assert len(ours) == len(bat["timestamp"]) > 0
    assert {s.instance for s in everything} == {d.multi_id + 1 for d in log.data_list if d.name == "battery_status"}
    start = log.start_timestamp  # the one clock: seconds since the log's start
    for sample, ts, volts in zip(ours, bat["timestamp"], bat["voltage_v"], strict=True):
        assert sample.t == pytest.approx((int(ts) - start) / 1e6)
        assert sample.battery.voltage_v == pytest.approx(float(volts), rel=1e-6)
        before = [a for t, a in zip(status["timestamp"], status["arming_state"], strict=True) if t <= ts]
        assert sample.armed == (bool(before) and before[-1] == 2)  # ARMING_STATE_ARMED


@pytest.mark.skipif(not REAL_LOGS.is_dir(), reason="real PX4 logs not present")
def test_real_ulog_replay(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    params = tmp_path / "p.param"
    params.write_text("BATT_LOW_VOLT,16.1\nBATT_LOW_TIMER,1\nBATT_FS_LOW_ACT,2\n", encoding="utf-8")
    found, err = events(capsys, "--params", str(params), str(REAL_LOGS / "sample_px4_events.ulg"))
    assert "157 samples" in err
    assert [(e["battery"], e["level"], e["outcome"]) for e in found] == [(1, "LOW", "hold")]


def test_jsonl_needs_params_and_empty_input_fails(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    stream = write_jsonl(tmp_path / "s.jsonl")
    assert main(["failsafe", str(stream)]) == 2
    assert "expected --params FILE" in capsys.readouterr().err
    params = tmp_path / "p.param"
    params.write_text("BATT_LOW_VOLT,10\n", encoding="utf-8")
    empty = tmp_path / "empty.jsonl"
    empty.write_text("# nothing\n", encoding="utf-8")
    assert main(["failsafe", "--params", str(params), str(empty)]) == 1  # readable but empty: the README's 1
    assert "expected battery readings, found none" in capsys.readouterr().err
    broken = tmp_path / "broken.bin"
    broken.write_bytes(b"\xa3\x95\x80" + b"\x00" * 10)
    # pymavlink's reader finds no record in it, as for report and export: a log without battery readings
    assert main(["failsafe", str(broken)]) == 1
    assert "expected battery readings, found none" in capsys.readouterr().err


def test_a_tlog_replays_with_its_own_parameter_download(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the PARAM_VALUE frames a ground station logged are the vehicle's parameters, as a .bin's PARM records are
    params = tmp_path / "rover.param"
    params.write_text("".join(f"{k},{v}\n" for k, v in PARAMS.items()), encoding="utf-8")
    given, _ = events(capsys, "--params", str(params), str(write_tlog(tmp_path / "flight.tlog")))
    own, err = events(capsys, str(write_tlog(tmp_path / "own.tlog", parameters=True)))
    assert "(PARAM_VALUE frames)" in err and "detected from CRUISE_SPEED" in err
    assert comparable(own) == comparable(given) and len(own) == 3
    assert main(["failsafe", str(tmp_path / "flight.tlog")]) == 2  # no download logged: --params is needed
    assert "carries no ArduPilot parameters of its own" in capsys.readouterr().err
