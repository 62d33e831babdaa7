"""The ArduPilot replay against what the firmware logged: ERR subsystem 6 and MODE reason 4 (ArduCopter/events.cpp
Copter::handle_battery_failsafe), on synthetic DataFlash logs and on every real ArduPilot log of ../shared (each
listed with the failsafe records it holds, read again with pymavlink); older parameter names and the older
firmware's disarmed check (the ArduCopter 3.4 tlog) said, not guessed."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from shared_data import require, shared

from codegen.apps.failsafe.ardupilot_logged import logged_failsafes
from codegen.apps.failsafe.legacy_parameters import renamed, with_current_names
from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from dataflash_writer import DataflashWriter

PARAMS = {"RTL_ALT": 1500.0, "BATT_MONITOR": 4.0, "BATT_LOW_VOLT": 10.5, "BATT_LOW_TIMER": 1.0, "BATT_FS_LOW_ACT": 2.0}


def copter_log(path: Path, *, failsafe_at: float | None, reason: bool = True) -> Path:
    """A Copter flight: armed at 0.5 s, BAT at 10 Hz, 10.4 V (below BATT_LOW_VOLT) from 2.0 s; the firmware's ERR and
    MODE (RTL, reason 4) at ``failsafe_at``."""
    w = DataflashWriter()
    w.define("PARM", "QNf", ("TimeUS", "Name", "Value"))
    w.define("ARM", "QBIb", ("TimeUS", "ArmState", "ArmChecks", "Method"))
    w.define("BAT", "QBfffffffBB", ("TimeUS", "Inst", "Volt", "VoltR", "Curr", "CurrTot", "EnrgTot", "Temp", "Res",
                                    "RemPct", "H"))  # fmt: skip
    w.define("ERR", "QBB", ("TimeUS", "Subsys", "ECode"))
    w.define(
        "MODE",
        "QBBB" if reason else "QBB",
        ("TimeUS", "Mode", "ModeNum", "Rsn") if reason else ("TimeUS", "Mode", "ModeNum"),
    )
    for name, value in PARAMS.items():
        w.write("PARM", 0, name, value)
    w.write("ARM", 500_000, 1, 0, 0)
    for k in range(1, 60):
        t = k / 10
        us = round(t * 1e6)
        w.write("BAT", us, 0, 10.4 if t >= 2.0 else 12.0, 10.4, 5.0, 0.0, 0.0, 25.0, 0.0, 0, 1)
        if failsafe_at is not None and abs(t - failsafe_at) < 1e-9:
            w.write("ERR", us + 1, 6, 1)
            w.write("MODE", us + 2, 6, 6, *((4,) if reason else ()))
    return w.save(path)


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["failsafe", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_a_logged_failsafe_is_reproduced(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # below 10.5 V from 2.0 s; LOW at the first sample more than BATT_LOW_TIMER (1 s) later: 3.1 s
    log = copter_log(tmp_path / "fs.bin", failsafe_at=3.1)
    code, out, err = run(capsys, "--strict", str(log))
    assert code == 0 and out.startswith("t=     3.100s  battery 1 LOW ") and "-> rtl" in out
    assert "check ERR subsystem 6 (FAILSAFE_BATT): reproduced (1 logged changes)" in err
    assert "check MODE for the battery failsafe (Rsn 4): reproduced (1 logged changes)" in err
    found = logged_failsafes(log, log.name, 100_000)  # the log's first record: 0.1 s
    assert [(round(r.t, 3), r.record) for r in found.records] == [(3.0, "ERR"), (3.0, "MODE")]


def test_a_failsafe_logged_elsewhere_differs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    late = copter_log(tmp_path / "late.bin", failsafe_at=4.5)
    code, _, err = run(capsys, "--strict", str(late))
    assert code == 3 and "check ERR subsystem 6 (FAILSAFE_BATT): DIFFERS: level 1 at 3.100s, logged at 4.500s" in err
    none = copter_log(tmp_path / "none.bin", failsafe_at=None)
    code, _, err = run(capsys, "--strict", str(none))
    assert code == 3 and "levels [] logged, [1] replayed" in err
    old = copter_log(tmp_path / "old.bin", failsafe_at=3.1, reason=False)
    code, _, err = run(capsys, str(old))
    assert code == 0 and "(Rsn 4): undecided: the log's MODE records carry no reason (Rsn)" in err


AP_LOGS = {  # every real ArduPilot DataFlash log of ../shared: the failsafe records it holds (ERR 6, MSG, MODE 4)
    "corpus/realworld3/dataflash/delorean_00000018.BIN": [],
    "corpus/realworld3/dataflash/dronekit_log171.bin": [],
    "corpus/realworld3/dataflash/methodic_backend_log_80k.bin": [],
    "corpus/realworld3/dataflash/robert_lefebvre_octo_PM.excerpt.log": [],
    "corpus/realworld3/dataflash/wlichon_baseline_20260406_010254.BIN": [],
    "corpus/realworld3b/dataflash/amc_backend_log_80k.bin": [],
    "corpus/realworld3b/dataflash/wlichon_00000001.BIN": [],
}


@pytest.mark.parametrize("name", sorted(AP_LOGS))
def test_real_logs_replay_what_they_logged(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    from pymavlink import mavutil

    path = require(shared(name))
    reference = mavutil.mavlink_connection(str(path))
    theirs = []
    while (msg := reference.recv_match(type=["ERR", "MODE", "MSG"])) is not None:
        if msg.get_type() == "ERR" and msg.Subsys == 6:
            theirs.append("ERR")
        elif msg.get_type() == "MODE" and getattr(msg, "Rsn", None) == 4:
            theirs.append("MODE")
        elif msg.get_type() == "MSG" and ("is low" in msg.Message or "is critical" in msg.Message):
            theirs.append("MSG")
    assert theirs == AP_LOGS[name]
    code, out, err = run(capsys, "--strict", str(path))  # the log's own parameters
    assert code == 0 and out == ""
    assert "check ERR subsystem 6 (FAILSAFE_BATT): reproduced (0 logged changes)" in err


def test_older_names_are_mapped_with_a_warning(capsys: pytest.CaptureFixture[str]) -> None:
    """QGroundControl's APMFirmwarePlugin remap for ArduCopter 3.6: FS_BATT_VOLTAGE -> BATT_LOW_VOLT, FS_BATT_MAH ->
    BATT_LOW_MAH, FS_BATT_ENABLE -> BATT_FS_LOW_ACT, ARMING_MIN_VOLT -> BATT_ARM_VOLT."""
    found = renamed({"FS_BATT_VOLTAGE": 14.0, "BATT_LOW_MAH": 300.0, "FS_BATT_MAH": 520.0, "ARMING_MIN_VOLT": 14.8})
    assert [r.message() for r in found] == [
        "FS_BATT_VOLTAGE = 14 is the older name of BATT_LOW_VOLT: replayed as BATT_LOW_VOLT = 14",
        "FS_BATT_MAH = 520 ignored: today's BATT_LOW_MAH = 300 is set too and wins",
        "ARMING_MIN_VOLT = 14.8 is the older name of BATT_ARM_VOLT: replayed as BATT_ARM_VOLT = 14.8",
    ]
    assert with_current_names({"FS_BATT_ENABLE": 2.0}) == {"FS_BATT_ENABLE": 2.0, "BATT_FS_LOW_ACT": 2.0}
    path = require(shared("corpus/realworld3/dataflash/dronekit_log171.bin"))  # ArduCopter 3.3
    code, _, err = run(capsys, str(path))
    assert code == 0
    assert "(PARM records): FS_BATT_VOLTAGE = 14 is the older name of BATT_LOW_VOLT: replayed as BATT_LOW_VOLT" in err


def test_the_34_tlog_warned_disarmed_which_the_replay_says(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # ArduCopter 3.4-dev with FS_BATT_VOLTAGE 14 on an 11.6 V pack: "Low battery" while disarmed (pymavlink's read);
    # today's AP_BattMonitor checks only while armed, so the replay has no event, and it says it cannot compare
    from pymavlink import mavutil

    source = require(shared("corpus/realworld3b/tlog/dronekit-la_fs-batt.log"))
    log = tmp_path / "fs-batt.tlog"
    log.write_bytes(source.read_bytes())
    reference = mavutil.mavlink_connection(str(log))
    armed, texts = [], []
    while (msg := reference.recv_match(type=["HEARTBEAT", "STATUSTEXT"])) is not None:
        if msg.get_type() == "HEARTBEAT" and msg.autopilot == 3:
            armed.append(bool(msg.base_mode & 128))
        elif msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
    assert "Low battery" in texts and not any(armed)
    code, out, err = run(capsys, str(log))
    assert code == 0 and out == ""
    assert "FS_BATT_VOLTAGE = 14 is the older name of BATT_LOW_VOLT" in err
    assert "check STATUSTEXT of the battery failsafe: undecided: a tlog records the failsafe as STATUSTEXT" in err
