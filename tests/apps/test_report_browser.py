"""``battgen report`` pages opened in headless Chromium: they load offline without errors, every expected plot
holds the points the data has (after the documented decimation), failsafe markers sit at the replayed times.

Pages: each shared real PX4 log, a synthetic one-hour 10 Hz two-battery flight, and a fleet page over several
logs. The screenshots are kept as test artefacts (see ``report_browser.py``); the load times are printed.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from flight_logs import write_capture_flight, write_flight
from report_browser import Page, open_page, require_browser
from shared_data import SHARED, real_logs, require
from test_report_log_facts import _commander_inputs

from codegen.apps.report.downsample import POINT_BUDGET, planned_length
from codegen.cli.main import main

pytest.importorskip("plotly")
REAL_LOGS = real_logs()


def _report(tmp_path: Path, name: str, *inputs: Path, extra: tuple[str, ...] = ()) -> Path:
    out = tmp_path / f"{name}.html"
    assert main(["report", *map(str, inputs), "-o", str(out), *extra]) == 0
    return out


def _check(page: Page, file_url: str) -> None:
    severe = [e for e in page.console if e.get("level") == "SEVERE"]
    assert severe == [], severe
    assert page.requests <= {file_url}, page.requests - {file_url}
    for plot in page.plots:
        for trace in plot["traces"]:
            if trace["samples"] is not None and trace["samples"] > POINT_BUDGET:
                assert trace["points"] == planned_length(trace["samples"]), trace
            else:
                assert trace["points"] >= (trace["samples"] or 0), trace


@pytest.mark.parametrize("log", REAL_LOGS, ids=[p.name for p in REAL_LOGS])
def test_real_log_report_in_browser(tmp_path: Path, capsys: pytest.CaptureFixture[str], log: Path) -> None:
    require_browser()
    out = _report(tmp_path, log.stem, log)
    page = open_page(out, f"report-{log.stem}")
    _check(page, out.resolve().as_uri())
    plots = [p for p in page.plots if p["id"].startswith("plot-")]
    assert plots and all(any(t["row"] == "pack voltage" for t in p["traces"]) for p in plots)
    print(f"{log.name}: rendered in {page.load_s:.2f} s")


def test_one_hour_two_battery_flight(tmp_path: Path) -> None:
    require_browser()
    log = write_flight(tmp_path / "hour.ulg", seconds=3600, hz=10, packs=2)
    out = _report(tmp_path, "hour", log)
    page = open_page(out, "report-one-hour-two-batteries")
    _check(page, out.resolve().as_uri())
    plots = [p for p in page.plots if p["id"].startswith("plot-")]
    assert len(plots) == 2
    for plot in plots:
        rows = {t["row"] for t in plot["traces"]}
        assert rows == {"pack voltage", "current", "power", "state of charge", "temperature", "cells", "cell imbalance"}
        voltage = next(t for t in plot["traces"] if t["row"] == "pack voltage")
        assert voltage["samples"] == 36000 and voltage["points"] == POINT_BUDGET
        assert sum(1 for t in plot["traces"] if t["row"] == "cells") == 6
    print(f"one hour, 10 Hz, two batteries: rendered in {page.load_s:.2f} s")


def test_fleet_page(tmp_path: Path) -> None:
    """Three flights of one DroneCAN pack (serial 777, ageing) beside the real logs: a row per flight and battery,
    and the pack's trends across its flights."""
    require_browser()
    captures = [
        write_capture_flight(tmp_path / f"flight{k}.log", health=95 - 3 * k, resistance=0.030 + 0.005 * k)
        for k in range(3)
    ]
    out = _report(tmp_path, "fleet", *captures, *REAL_LOGS)
    page = open_page(out, "report-fleet")
    _check(page, out.resolve().as_uri())
    batteries = [p for p in page.plots if p["id"].startswith("plot-")]
    assert len(batteries) == 3 + sum({"sample_log_small.ulg": 2}.get(p.name, 1) for p in REAL_LOGS)
    trends = next(p for p in page.plots if p["id"] == "trends")
    assert {t["row"] for t in trends["traces"]} == {
        "charge used [mAh]",
        "internal resistance [mΩ]",
        "state of health [%]",
    }
    assert {t["name"] for t in trends["traces"]} == {"pack 777"}
    assert all(t["points"] == 3 for t in trends["traces"])


PARAMS = """# a copter with two 6S packs: LOW at 3.5 V/cell -> RTL, CRITICAL at 3.3 V/cell -> Land
BATT_MONITOR,4
BATT_CAPACITY,10000
BATT_LOW_VOLT,21.0
BATT_CRT_VOLT,19.8
BATT_FS_LOW_ACT,2
BATT_FS_CRT_ACT,1
BATT2_MONITOR,4
BATT2_CAPACITY,10000
BATT2_LOW_VOLT,21.0
BATT2_CRT_VOLT,19.8
BATT2_FS_LOW_ACT,2
BATT2_FS_CRT_ACT,1
"""


def test_failsafe_markers_sit_at_the_replayed_times(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The page's marker lines are ``battgen failsafe``'s events on the same log and parameters."""
    require_browser()
    log = write_flight(tmp_path / "failsafe.ulg", seconds=600, hz=10, packs=2, armed=(5, 590))
    params = tmp_path / "copter.param"
    params.write_text(PARAMS)
    capsys.readouterr()
    assert main(["failsafe", "--params", str(params), "--vehicle", "copter", "--json", str(log)]) == 0
    events = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert {e["level"] for e in events} == {"LOW", "CRITICAL"}
    out = _report(tmp_path, "failsafe", log, extra=("--params", str(params), "--vehicle", "copter"))
    page = open_page(out, "report-failsafe")
    _check(page, out.resolve().as_uri())
    plots = [p for p in page.plots if p["id"].startswith("plot-")]
    for battery, plot in enumerate(plots, start=1):
        expected = [(e["level"], e["t"]) for e in events if e["battery"] == battery]
        got = [(m["level"], m["t"]) for m in plot["markers"]]
        assert [level for level, _ in got] == [level for level, _ in expected]
        assert [t for _, t in got] == pytest.approx([t for _, t in expected], abs=1e-6)


PX4_WARNINGS = SHARED / "corpus" / "realworld3" / "ulog" / "fsyrh_log_61_2024-2-6-16-27-02.ulg"  # warnings 0..3
ARDUPILOT = SHARED / "corpus" / "realworld3" / "dataflash" / "dronekit_log171.bin"


def test_the_log_speaks_first_in_the_browser(tmp_path: Path) -> None:
    """A PX4 log whose battery went low, critical and emergency, and an ArduPilot DataFlash log: the header, the
    armed shading and the log's own warning markers as the live page holds them, against pyulog's and pymavlink's
    reads of the same topics and records."""
    require_browser()
    pyulog = pytest.importorskip("pyulog")
    mavutil = pytest.importorskip("pymavlink.mavutil")
    log = require(PX4_WARNINGS)
    out = _report(tmp_path, "px4-warnings", log)
    page = open_page(out, "report-px4-warnings")
    _check(page, out.resolve().as_uri())
    ulog = pyulog.ULog(str(log), ["battery_status", "vehicle_status", "failsafe_flags"])
    (header,) = page.headers
    assert header["hardware"] == ulog.msg_info_dict["ver_hw"]
    assert f"({ulog.msg_info_dict['ver_sw'][:8]})" in header["firmware"]
    (status,) = [d for d in ulog.data_list if d.name == "vehicle_status"]
    armed_at = (
        status.data["timestamp"][status.data["arming_state"] == 2].astype(np.int64) - ulog.start_timestamp
    ) / 1e6
    (plot,) = [p for p in page.plots if p["id"].startswith("plot-")]
    (battery,) = [d for d in ulog.data_list if d.name == "battery_status"]
    codes = battery.data["warning"].tolist()
    times = ((battery.data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6).tolist()
    within = [t for t in armed_at.tolist() if 0 <= t <= times[-1]]  # the shading spans the log from t = 0 to its end
    assert plot["armed"] and all(any(a <= t <= b for a, b in plot["armed"]) for t in within)
    levels = ("none", "low", "critical", "emergency")  # battery_status WARNING_NONE..WARNING_EMERGENCY
    expected = [(t, levels[c]) for k, (t, c) in enumerate(zip(times, codes, strict=True)) if k and c != codes[k - 1]]
    assert [w["level"] for w in plot["warnings"]] == [level for _, level in expected]
    assert [w["t"] for w in plot["warnings"]] == pytest.approx([t for t, _ in expected], abs=1e-6)
    nav, stamps = status.data["nav_state"], (status.data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6
    changes = [max(float(stamps[k]), 0.0) for k in range(len(nav)) if k == 0 or nav[k] != nav[k - 1]]
    assert [m["t"] for m in plot["modes"]] == pytest.approx([t for t in changes if t < times[-1]], abs=1e-6)
    flags = status.data["failsafe"]
    rising = [float(stamps[k]) for k in range(1, len(flags)) if flags[k] and not flags[k - 1]]
    rising = sorted(rising + _commander_inputs(ulog, times[-1]))  # and commander's battery inputs (failsafe_flags)
    assert [f["t"] for f in plot["failsafes"]] == pytest.approx(rising, abs=1e-6) and rising
    shutil.copy(page.screenshot, tmp_path / "kept.png")  # the screenshot is the artefact a person looks at

    log = require(ARDUPILOT)
    out = _report(tmp_path, "ardupilot", log)
    page = open_page(out, "report-ardupilot")
    _check(page, out.resolve().as_uri())
    reader = mavutil.mavlink_connection(str(log))
    firmware = None
    while firmware is None and (m := reader.recv_match(type="MSG")) is not None:
        firmware = m.Message if m.Message.startswith(("APM", "ArduCopter", "ArduPlane", "ArduRover")) else None
    (header,) = page.headers
    assert firmware is not None and firmware in header["firmware"]
    assert "duration" in header and header.get("log start")
    # the log's EV records as markers: one per record (this log's all fall within its battery records), and the
    # ARMED event where the armed shading starts (the arming rule reads the same record)
    reader = mavutil.mavlink_connection(str(log))
    events = sum(1 for _ in iter(lambda: reader.recv_match(type="EV"), None))
    (plot,) = [p for p in page.plots if p["id"].startswith("plot-")]
    assert len(plot["events"]) == events > 0
    (armed_at,) = [e["t"] for e in plot["events"] if e["what"] == "ARMED"]
    assert plot["armed"] and plot["armed"][0][0] == pytest.approx(armed_at, abs=1e-6)
