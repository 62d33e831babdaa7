"""The report's header, armed shading, the log's own warning markers and parameter table agree with the log, read
independently by pyulog (PX4) and pymavlink (ArduPilot DataFlash), on every real log of ``../shared``; plots a
person reads (SoC on 0-100 %, cell legends, figures with their precision, no per-cell data where there is none)."""

from __future__ import annotations

import dataclasses
import json
import re
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from shared_data import SHARED, real_logs, require

from codegen.apps.battery.context import LogContext
from codegen.apps.report.build import collect, html
from codegen.apps.report.figures import NO_CELLS, compute, shown
from codegen.apps.report.fleet import fleet_view
from codegen.apps.report.log_facts import BATTERY_PARAMETER, log_facts
from codegen.apps.report.plots import figure
from codegen.apps.report.series import BatterySeries
from codegen.apps.schemas.package import bundled_schemas

pyulog = pytest.importorskip("pyulog")
pytest.importorskip("plotly")

_by_name: dict[str, Path] = {}
for _p in [*real_logs(), *sorted(SHARED.glob("corpus/realworld3*/ulog/*.ulg"))]:
    _by_name.setdefault(_p.name, _p)  # realworld3b repeats some of realworld3's logs
ULOGS = sorted(_by_name.values(), key=lambda p: p.name)
FLEET_PX4 = SHARED / "corpus" / "realworld3" / "ulog" / "fsyrh_log_123_2024-3-1-14-47-02.ulg"  # 559 mAh used
UORB_WARNINGS = ("none", "low", "critical", "emergency", "failed")  # battery_status WARNING_* 0..4 (BatteryStatus.msg)
ARMING_STATE_ARMED = 2  # vehicle_status ARMING_STATE_ARMED (VehicleStatus.msg)
# ArduPilot ModeReason (AP_Vehicle/ModeReason.h), the ones these logs give
MODE_REASON_NAMES = {0: "UNKNOWN", 1: "RC_COMMAND", 2: "GCS_COMMAND", 3: "RADIO_FAILSAFE", 4: "BATTERY_FAILSAFE"}
# ArduPilot LogEvent (AP_Logger/AP_Logger.h), the ids these logs' EV records give; 8 and 16 are older firmware's
# DATA_SYSTEM_TIME_SET and DATA_TAKEOFF
LOG_EVENT_NAMES = {
    8: "SYSTEM_TIME_SET",
    10: "ARMED",
    11: "DISARMED",
    15: "AUTO_ARMED",
    16: "TAKEOFF",
    25: "SET_HOME",
    28: "NOT_LANDED",
    56: "MOTORS_INTERLOCK_DISABLED",
    57: "MOTORS_INTERLOCK_ENABLED",
    62: "EKF_YAW_RESET",
}


def _page(path: Path) -> tuple[Any, dict[str, Any]]:
    report = collect([path], bundled_schemas())
    text = html(report)
    block = re.search(r'<script id="figures" type="application/json">(.*?)</script>', text, re.S)
    assert block is not None
    return report, json.loads(block.group(1).replace("<\\/", "</"))


def _shapes(figures: dict[str, Any], prefix: str) -> list[dict[str, Any]]:
    return [
        s
        for key, fig in figures.items()
        if key.startswith("plot-")
        for s in fig["layout"]["shapes"]
        if s.get("name", "").startswith(prefix)
    ]


def _flat(spans: list[tuple[float, float]]) -> list[float]:
    return [x for span in spans for x in span]


def _expected_arming(ulog: Any, end: float) -> list[tuple[float, float]]:
    status = [d for d in ulog.data_list if d.name == "vehicle_status"]
    if not status:
        return []
    t = (status[0].data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6
    armed = status[0].data["arming_state"] == ARMING_STATE_ARMED
    spans: list[tuple[float, float]] = []
    since = None
    for tk, a in zip(t.tolist(), armed.tolist(), strict=True):
        if a and since is None:
            since = max(tk, 0.0)
        elif not a and since is not None:
            spans.append((since, max(tk, 0.0)))
            since = None
    if since is not None and end > since:
        spans.append((since, end))
    return spans


def _expected_warnings(ulog: Any) -> list[tuple[float, str]]:
    out = []
    for d in ulog.data_list:
        if d.name != "battery_status":
            continue
        last = None
        t = (d.data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6
        for tk, code in zip(t.tolist(), d.data["warning"].tolist(), strict=True):
            if code != last and (last is not None or code != 0):
                out.append((tk, UORB_WARNINGS[code]))
            last = code
    return sorted(out)


@pytest.mark.parametrize("log", ULOGS, ids=[p.name for p in ULOGS])
def test_px4_header_shading_warnings_and_parameters_agree_with_pyulog(log: Path) -> None:
    topics = ["battery_status", "vehicle_status", "vehicle_gps_position", "failsafe_flags"]
    ulog = pyulog.ULog(str(log), topics)  # texts: always read
    if not any(d.name == "battery_status" for d in ulog.data_list):
        pytest.skip(f"{log.name} logs no battery_status")
    report, figures = _page(log)
    (item,) = report.inputs
    facts = report.facts[item.source]
    header = dict(facts.header)
    info = ulog.msg_info_dict
    assert header["hardware"] == info["ver_hw"]
    assert f"({info['ver_sw'][:8]})" in header["firmware"] and header["firmware"].startswith(
        info.get("sys_name", "PX4")
    )
    if "MAV_TYPE" in ulog.initial_parameters:
        assert header["vehicle type"].endswith(f"(MAV_TYPE {int(ulog.initial_parameters['MAV_TYPE'])})")
    gps = [d for d in ulog.data_list if d.name == "vehicle_gps_position"]
    stamps = gps[0].data["time_utc_usec"] if gps else np.zeros(0)
    if len(np.flatnonzero(stamps)):
        k = int(np.flatnonzero(stamps)[0])
        utc = int(stamps[k]) - (int(gps[0].data["timestamp"][k]) - ulog.start_timestamp)
        shown_start = datetime.strptime(header["log start"], "%Y-%m-%d %H:%M:%S UTC").replace(tzinfo=UTC)
        assert abs(shown_start.timestamp() - utc / 1e6) <= 1.0
    end = max(float(s.t[-1]) for s in item.batteries)
    expected = _expected_arming(ulog, end)
    got = sorted({(s["x0"], s["x1"]) for s in _shapes(figures, "armed")})
    assert _flat(got) == pytest.approx(_flat(expected), abs=1e-6)
    warnings = sorted({(s["x0"], s["name"].removeprefix("log warning ")) for s in _shapes(figures, "log warning")})
    assert [w for _, w in warnings] == [w for _, w in _expected_warnings(ulog)]
    assert [t for t, _ in warnings] == pytest.approx([t for t, _ in _expected_warnings(ulog)], abs=1e-6)
    params = {k: v for k, v in ulog.initial_parameters.items() if BATTERY_PARAMETER.match(k)}
    assert [name for name, _ in facts.parameters] == sorted(params)
    for name, text in facts.parameters:
        assert float(text) == pytest.approx(params[name], rel=1e-6)
    _px4_modes_texts_failsafes(ulog, facts, figures, end)
    for name in ("BAT_LOW_THR", "BAT_CRIT_THR", "BAT_EMERGEN_THR"):
        if params.get(name, 0) > 0:
            assert facts.soc_thresholds[name] == pytest.approx(params[name] * 100, rel=1e-6)
            assert facts.thresholds_from == "the log's PARAM definitions"


def _px4_modes_texts_failsafes(ulog: Any, facts: Any, figures: dict[str, Any], end: float) -> None:
    """Flight modes (nav_state changes), failsafe entries (vehicle_status.failsafe turning true) and logged
    messages, as pyulog reads them, against the page."""
    tagged = [(m.timestamp, m.message) for messages in ulog.logged_messages_tagged.values() for m in messages]
    texts = sorted([(m.timestamp, m.message) for m in ulog.logged_messages] + tagged, key=lambda m: m[0])
    assert [m.text for m in facts.texts] == [text.rstrip("\t\n\x00") for _, text in texts]
    assert [m.t for m in facts.texts] == pytest.approx([(stamp - ulog.start_timestamp) / 1e6 for stamp, _ in texts])
    status = [d for d in ulog.data_list if d.name == "vehicle_status"]
    if not status:
        assert facts.modes == [] and facts.failsafes == []
        return
    t = np.maximum((status[0].data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6, 0.0)
    nav = status[0].data["nav_state"]
    changes = [k for k in range(len(nav)) if k == 0 or nav[k] != nav[k - 1]]
    want_modes = [(float(t[k]), int(nav[k])) for k in changes if t[k] <= end]
    assert [m for m, _ in facts.modes] == pytest.approx([m for m, _ in want_modes], abs=1e-6)
    assert all(
        name.endswith(str(code)) or not name.startswith("nav_state")
        for (_, name), (_, code) in zip(facts.modes, want_modes, strict=True)
    )
    bands = sorted({s["x0"] for s in _shapes(figures, "mode ")})
    assert bands == pytest.approx(sorted({m for m, _ in facts.modes if m < end}), abs=1e-6)
    flags = status[0].data["failsafe"]
    rising = [float(t[k]) for k in range(len(flags)) if flags[k] and (k == 0 or not flags[k - 1]) and t[k] <= end]
    rising = sorted(rising + _commander_inputs(ulog, end))
    assert [f for f, _ in facts.failsafes] == pytest.approx(rising, abs=1e-6)
    assert sorted({s["x0"] for s in _shapes(figures, "log failsafe")}) == pytest.approx(sorted(set(rising)), abs=1e-6)


def _commander_inputs(ulog: Any, end: float) -> list[float]:
    """The times failsafe_flags.battery_warning rises and battery_low_remaining_time turns true (PX4 v1.14+)."""
    flagged = [d for d in ulog.data_list if d.name == "failsafe_flags" and d.multi_id == 0]
    if not flagged:
        return []
    data = flagged[0].data
    t = np.maximum((data["timestamp"].astype(np.int64) - ulog.start_timestamp) / 1e6, 0.0)
    low = data.get("battery_low_remaining_time", np.zeros(len(t)))
    out: list[float] = []
    level, was_low = 0, False
    for tk, warning, flag in zip(t.tolist(), data["battery_warning"].tolist(), low.tolist(), strict=True):
        if warning > level and warning in (1, 2, 3) and tk <= end:
            out.append(tk)
        level = warning
        if flag and not was_low and tk <= end:
            out.append(tk)
        was_low = bool(flag)
    return out


DATAFLASH = sorted(SHARED.glob("corpus/realworld3*/dataflash/*.[bB][iI][nN]"))


@pytest.mark.parametrize("log", DATAFLASH, ids=[p.name for p in DATAFLASH])
def test_ardupilot_header_and_parameters_agree_with_pymavlink(log: Path) -> None:
    mavutil = pytest.importorskip("pymavlink.mavutil")
    reader = mavutil.mavlink_connection(str(log))
    params: dict[str, float] = {}
    firmware = None
    texts: list[str] = []
    modes: list[tuple[int, int | None]] = []
    errors: list[tuple[int, int]] = []
    while (m := reader.recv_match(type=["PARM", "MSG", "MODE", "ERR"])) is not None:
        if m.get_type() == "PARM":
            params[m.Name] = m.Value
        elif m.get_type() == "MODE":
            modes.append((m.ModeNum, getattr(m, "Rsn", None)))
        elif m.get_type() == "ERR":
            errors.append((m.Subsys, m.ECode))
        else:
            texts.append(m.Message)
            if firmware is None and re.match(r"(APM|ArduPilot|Ardu)\S*[: ]", m.Message):
                firmware = m.Message
    try:
        report, figures = _page(log)
    except Exception as exc:  # a log without battery records: the report says so, nothing to compare
        pytest.skip(f"{log.name}: {exc}")
    (item,) = report.inputs
    facts = report.facts[item.source]
    header = dict(facts.header)
    if firmware is not None:
        assert firmware.split()[0] in header["firmware"]
    wanted = {k: v for k, v in params.items() if BATTERY_PARAMETER.match(k)}
    assert [name for name, _ in facts.parameters] == sorted(wanted)
    for name, text in facts.parameters:
        assert float(text) == pytest.approx(wanted[name], rel=1e-6, abs=1e-9)
    context = item.context
    assert isinstance(context, LogContext) and context.autopilot == "ardupilot"
    assert [m.text for m in context.texts] == texts
    assert len(context.modes) == len(modes)
    mapping = mavutil.mode_mapping_bynumber(2 if "Copter" in (firmware or "") else 1) or {}
    for (_, name), (number, reason) in zip(context.modes, modes, strict=True):
        assert name.startswith(mapping.get(number, f"mode {number}"))
        assert reason is None or reason not in MODE_REASON_NAMES or name.endswith(f"({MODE_REASON_NAMES[reason]})")
    failsafe_modes = sum(1 for _, reason in modes if reason in (3, 4, 5, 6, 11, 19, 25))
    failsafe_errors = sum(1 for subsystem, code in errors if 5 <= subsystem <= 9 and code != 0)
    assert len(context.failsafes) == failsafe_modes + failsafe_errors
    end = max(float(s.t[-1]) for s in item.batteries)
    got = sorted({(s["x0"], s["x1"]) for s in _shapes(figures, "armed")})
    assert _flat(got) == pytest.approx(_flat(context.armed_intervals(end)), abs=1e-6)
    # every EV record, named as AP_Logger names it, at its time on the log's clock: its TimeUS, or before 3.4 (no
    # time field) pymavlink's clock at the record in a walk of every record, zero-based as the battery view reads
    # it. The view's walk reads fewer types, so its clock there is the last battery/GPS/arming record's: within
    # 0.1 s of the full walk's (those records come at 5-10 Hz).
    from pymavlink import DFReader

    events: list[tuple[float, int]] = []  # (µs, Id)
    timeless = False
    ev_reader = DFReader.DFReader_binary(str(log), zero_time_base=True)
    while (m := ev_reader.recv_match(type=["EV"])) is not None:
        timeless = timeless or "TimeUS" not in m.to_dict()
        events.append((float(getattr(m, "TimeUS", 0)), m.Id))
    if timeless:
        ev_reader = DFReader.DFReader_binary(str(log), zero_time_base=True)
        events = [(m._timestamp * 1e6, m.Id) for m in iter(ev_reader.recv_msg, None) if m.get_type() == "EV"]
    origin = context.start_us or 0
    tolerance = 0.1 if timeless else 1e-6
    expected = [(max((stamp - origin) / 1e6, 0.0), LOG_EVENT_NAMES[event]) for stamp, event in events]
    assert [name for _, name in context.events] == [name for _, name in expected]
    assert [t for t, _ in context.events] == pytest.approx([t for t, _ in expected], abs=tolerance)
    shown = [(t, name) for t, name in context.events if t <= end]
    assert facts.events == shown
    marked = sorted(s["x0"] for s in _shapes(figures, "log event"))
    assert marked == pytest.approx(sorted(t for t, _ in shown) * len(item.batteries), abs=1e-6)


def _series(pack: list[float], cells: list[list[float]], soc: list[float]) -> BatterySeries:
    s = BatterySeries("x", 0, "id", "uorb.BatteryStatus")
    n = len(pack)
    s.t = np.arange(n, dtype=np.float64)
    s.pack_voltage = np.array(pack)
    s.cells = np.array(cells)
    s.state_of_charge = np.array(soc)
    for name in ("current", "temperature", "discharged", "remaining_energy", "charge_c", "energy_j", "armed"):
        setattr(s, name, np.full(n, np.nan))
    s.warning = np.zeros(n)
    return s


def test_plots_a_person_reads() -> None:
    even = _series([12.0, 11.9, 11.8], [[4.0] * 3, [11.9 / 3] * 3, [11.8 / 3] * 3], [99.98, 99.96, 99.94])
    fig = figure(even)
    rows = {t["meta"]["row"] for t in fig["data"]}
    assert even.cells_split_evenly and rows == {"pack voltage", "state of charge"}
    soc_axis = next(k for k, v in fig["layout"].items() if k.startswith("yaxis") and "state of charge" in str(v))
    assert fig["layout"][soc_axis]["range"] == [0, 100]
    figures = dict(compute(even).rows(per_cell=False))
    assert figures["minimum cell voltage"] == figures["max cell imbalance"] == NO_CELLS
    measured = _series([12.0, 11.9, 11.8], [[4.0, 4.01, 3.99]] * 3, [50.0, 49.0, 48.0])
    fig = figure(measured)
    cells = [t for t in fig["data"] if t["meta"]["row"] == "cells"]
    assert not measured.cells_split_evenly and len(cells) == 3
    assert fig["layout"]["showlegend"] and all(t["showlegend"] for t in cells)
    assert not any(t["showlegend"] for t in fig["data"] if t["meta"]["row"] != "cells")
    assert [shown(v, 0) for v in (0.39, 12.3, 1234.0)] == ["0.39", "12", "1234"]
    assert shown(0.0004, 1) == "0.00040"


def test_params_override_the_logs_thresholds(tmp_path: Path) -> None:
    context = LogContext("ulog", autopilot="px4", parameters={"BAT_LOW_THR": 0.15, "BAT_CRIT_THR": 0.07})
    facts = log_facts(context, 10.0)
    assert facts.soc_thresholds == pytest.approx({"BAT_LOW_THR": 15.0, "BAT_CRIT_THR": 7.0})
    assert facts.thresholds_from == "the log's PARAM definitions"
    facts = log_facts(context, 10.0, {"BAT_LOW_THR": 0.25}, "my.params")
    assert facts.soc_thresholds == {"BAT_LOW_THR": 25.0} and facts.thresholds_from == "my.params"


def test_fleet_rows_carry_date_and_firmware_and_trends_run_over_dates() -> None:
    """Two flights of one pack: each row has the log's start (UTC) and firmware from its context; the pack's
    trend is plotted over those dates, in date order whatever the input order."""
    log = require(FLEET_PX4)
    first, second = (collect([log], bundled_schemas()).inputs[0] for _ in range(2))
    for item, start in ((first, 1_710_000_000_000_000), (second, 1_700_000_000_000_000)):
        assert item.samples is not None and item.samples.context is not None
        item.samples.context = dataclasses.replace(item.samples.context, start_us=0, utc_offset_us=start)
        for s in item.batteries:
            s.serial = "4242"
    view = fleet_view([first, second])
    date, firmware = view.header.index("date [UTC]"), view.header.index("firmware")
    assert [row[date] for row in view.rows] == ["2024-03-09 16:00:00", "2023-11-14 22:13:20"]
    assert first.samples.context.firmware.startswith("PX4 v1.14.0")
    assert {row[firmware] for row in view.rows} == {first.samples.context.firmware}
    (trace, *_) = view.trends["data"]
    assert trace["x"] == ["2023-11-14 22:13:20", "2024-03-09 16:00:00"]
    assert view.trends["layout"]["xaxis"]["type"] == "date"


def test_fleet_cell_columns_say_what_the_battery_figures_say() -> None:
    """A log whose cells are its pack voltage split evenly (PX4 1.11's sample log) has no per-cell data: its fleet
    row leaves the cell columns empty ("—"), as its battery's figures say "no per-cell data", never 0 mV."""
    log = require(SHARED / "data" / "ulog" / "sample_log_small.ulg")
    (item,) = collect([log], bundled_schemas()).inputs
    view = fleet_view([item])
    cell, imbalance = view.header.index("min cell [V]"), view.header.index("max imbalance [mV]")
    assert item.batteries and all(s.cells_split_evenly for s in item.batteries)
    for row, s in zip(view.rows, item.batteries, strict=True):
        figures = dict(compute(s).rows(per_cell=s.has_cell_data))
        assert figures["max cell imbalance"] == NO_CELLS
        assert row[cell] == row[imbalance] == "—"
