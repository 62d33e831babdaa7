"""What a log says about itself (:class:`codegen.apps.battery.context.LogContext`, stated once by the battery view's
read) against the reference readers on every real log of ``../shared``:

- PX4 ULog, against pyulog: the vehicle (``sys_uuid``), the release ``ver_sw_release`` decodes to
  (``ULog.get_version_info``), the hardware, every initial parameter (a float32 value as its shortest decimal,
  equal as a float32), and the arming changes (``vehicle_status.arming_state`` ARMED, else ``actuator_armed``);
- ArduPilot DataFlash, against pymavlink's DFReader: every ``PARM`` value as the reader holds it after the whole
  log (``DFReader.params``: a value set again in flight takes its last), and the firmware the ``VER`` record names
  (where the log has one);
- MAVLink tlog, against pymavlink: the MAV_TYPE and MAV_AUTOPILOT of each system's last vehicle heartbeat
  (pymavlink's ``probably_vehicle_heartbeat``) and every PARAM_VALUE (the last of each name);
- one flight's DataFlash log and tlog (``wlichon_baseline_20260406_010254``): the same parameters, but for one the
  vehicle learns in flight.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from shared_data import SHARED, missing

from codegen.apps.battery.context import LogContext
from codegen.apps.battery.tlog_batches import parameter_name
from codegen.apps.battery.view import read_view
from codegen.inputs.files.kinds import detect

pyulog = pytest.importorskip("pyulog")


def _logs(kind: str) -> list[Path]:
    seen: set[bytes] = set()
    out = []
    for path in sorted(SHARED.joinpath("data").rglob("*")) + sorted(SHARED.joinpath("corpus").rglob("*")):
        if not path.is_file() or "upstream" in path.parts or path.stat().st_size == 0 or detect(path) != kind:
            continue
        head = path.read_bytes()[:65536] + str(path.stat().st_size).encode()
        if head not in seen:
            seen.add(head)
            out.append(path)
    return out


ULOGS, DATAFLASH, TLOGS = _logs("ulog"), _logs("dataflash"), _logs("tlog")


def test_every_kind_is_present() -> None:
    if not (ULOGS and DATAFLASH and TLOGS):
        missing("the real ULogs, DataFlash logs and tlogs of ../shared")


def _contexts(path: Path) -> list[LogContext]:
    """Each distinct context the view's chunks carry (one per log; a tlog: one per system)."""
    out: list[LogContext] = []
    for chunk in read_view(path):
        context = chunk.batch.context
        assert context is not None, "every chunk of a log carries its context"
        if all(context is not c for c in out):
            out.append(context)
    return out


def _same_float32(a: float, b: float) -> bool:
    return bool(np.float32(a) == np.float32(b)) or a == b


@pytest.mark.parametrize("path", ULOGS, ids=[p.name for p in ULOGS])
def test_ulog_context_matches_pyulog(path: Path) -> None:
    contexts = _contexts(path)
    if not contexts:  # no battery record, so no chunk to carry the context: pyulog finds none either
        assert not pyulog.ULog(str(path), ["battery_status"]).data_list
        return
    (context,) = contexts
    log = pyulog.ULog(str(path), ["vehicle_status", "actuator_armed"])
    info = log.msg_info_dict
    assert context.vehicle == (str(info["sys_uuid"]) if info.get("sys_uuid") else None)
    assert context.hardware == (info.get("ver_hw") or None)
    assert context.start_us == log.start_timestamp
    version = log.get_version_info()
    if version is not None and any(version):
        assert context.firmware is not None and f"v{version[0]}.{version[1]}.{version[2]}" in context.firmware
    if info.get("ver_sw"):
        assert context.firmware is not None and f"({info['ver_sw'][:8]})" in context.firmware
    theirs = log.initial_parameters
    assert set(context.parameters) == set(theirs)
    for name, value in theirs.items():
        assert _same_float32(context.parameters[name], float(value)), name
    assert context.vehicle_type == (int(theirs["MAV_TYPE"]) if "MAV_TYPE" in theirs else None)
    assert context.arming == _pyulog_arming(log)


def _pyulog_arming(log: object) -> tuple[tuple[float, bool], ...]:
    data = {d.name: d.data for d in log.data_list if d.multi_id == 0}  # type: ignore[attr-defined]
    if "vehicle_status" in data:
        stamps, armed = data["vehicle_status"]["timestamp"], data["vehicle_status"]["arming_state"] == 2
    elif "actuator_armed" in data:
        stamps, armed = data["actuator_armed"]["timestamp"], data["actuator_armed"]["armed"] != 0
    else:
        return ()
    out: list[tuple[float, bool]] = []
    start = log.start_timestamp  # type: ignore[attr-defined]
    for stamp, state in sorted(zip(stamps.tolist(), armed.tolist(), strict=True), key=lambda x: x[0]):
        if not out or out[-1][1] != bool(state):
            out.append((max((int(stamp) - start) / 1e6, 0.0), bool(state)))
    return tuple(out)


@pytest.mark.parametrize("path", DATAFLASH, ids=[p.name for p in DATAFLASH])
def test_dataflash_parameters_match_pymavlink(path: Path) -> None:
    from pymavlink import DFReader

    contexts = _contexts(path)
    if not contexts:
        pytest.skip("no battery records: the view yields no chunk")
    (context,) = contexts
    text = path.suffix.lower() != ".bin"
    reader = (DFReader.DFReader_text if text else DFReader.DFReader_binary)(str(path), zero_time_base=True)
    version = None
    while (msg := reader.recv_match(type=["PARM", "VER"])) is not None:
        if msg.get_type() == "VER" and version is None:
            version = msg.FWS  # the firmware's own version record (ArduPilot 4.1 on)
    assert context.autopilot == "ardupilot"
    if version:
        assert context.firmware == version  # the start-up MSG we read names what VER records
    assert set(context.parameters) == set(reader.params)
    for name, value in reader.params.items():
        assert _same_float32(context.parameters[name], float(value)), name


@pytest.mark.parametrize("path", TLOGS, ids=[p.name for p in TLOGS])
def test_tlog_vehicle_matches_pymavlink(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MAVLINK20", "1")  # its MAVLink 2 parser, which reads MAVLink 1 frames too
    from pymavlink import mavutil

    mavutil.set_dialect("ardupilotmega")
    conn = mavutil.mavmmaplog(str(path))  # what mavlink_connection opens for a .tlog
    last: dict[int, tuple[int, int]] = {}
    params: dict[int, dict[str, float]] = {}
    while (msg := conn.recv_match(type=["HEARTBEAT", "PARAM_VALUE"])) is not None:
        if msg.get_type() == "PARAM_VALUE":
            name = parameter_name(msg.param_id)  # pymavlink keeps a junk byte after a name (as U+FFFD)
            if name:
                params.setdefault(msg.get_srcSystem(), {})[name] = msg.param_value
        elif conn.probably_vehicle_heartbeat(msg):
            last[msg.get_srcSystem()] = (msg.type, msg.autopilot)
    conn.close()
    contexts = _contexts(path)
    if not contexts:
        pytest.skip("no battery records: the view yields no chunk")
    for context in contexts:
        assert context.vehicle is not None and context.vehicle.startswith("mavlink:")
        sysid = int(context.vehicle.split(":")[1])
        theirs = params.get(sysid, {})
        assert set(context.parameters) == set(theirs)
        if context.autopilot != "px4":  # ArduPilot sends the number itself (PX4's integers: their bytes)
            for name, value in theirs.items():
                assert _same_float32(context.parameters[name], float(value)), name
        if sysid not in last:
            assert context.vehicle_type is None and context.arming == ()
            continue
        mav_type, autopilot = last[sysid]
        assert context.vehicle_type == mav_type
        assert context.autopilot == {3: "ardupilot", 12: "px4"}.get(autopilot)


def test_one_flights_dataflash_and_tlog_hold_the_same_parameters() -> None:
    """The vehicle's PARM records and what the ground station downloaded (PARAM_VALUE) of the same flight agree, but
    for MOT_THST_HOVER, which ArduCopter learns in flight (the two logs end at different moments of it)."""
    pair = [p for p in DATAFLASH + TLOGS if p.stem == "wlichon_baseline_20260406_010254"]
    if len(pair) != 2:
        missing("wlichon_baseline_20260406_010254.BIN and .tlog")
    (dataflash,), (tlog,) = _contexts(pair[0]), _contexts(pair[1])
    assert dataflash.parameters.keys() == tlog.parameters.keys() and len(tlog.parameters) > 1000
    differ = {k for k in tlog.parameters if tlog.parameters[k] != dataflash.parameters[k]}
    assert differ == {"MOT_THST_HOVER"}
    assert tlog.parameters["BATT_LOW_VOLT"] == 10.5 and tlog.parameters["BATT_CAPACITY"] == 3300.0


@pytest.mark.parametrize("path", TLOGS, ids=[p.name for p in TLOGS])
def test_tlog_modes_and_texts_match_pymavlink(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each change of a system's mode as pymavlink names it (``mode_string_v10`` of its vehicle heartbeats) and
    its STATUSTEXTs with their severity, at the tlog's own stamps."""
    monkeypatch.setenv("MAVLINK20", "1")
    from pymavlink import mavutil

    mavutil.set_dialect("ardupilotmega")
    conn = mavutil.mavmmaplog(str(path))
    modes: dict[int, list[tuple[float, str]]] = {}
    texts: dict[int, list[tuple[float, int, str]]] = {}
    while (msg := conn.recv_match()) is not None:
        stamp = getattr(msg, "_timestamp", None)
        kind = msg.get_type()
        if kind == "HEARTBEAT" and conn.probably_vehicle_heartbeat(msg):
            seen = modes.setdefault(msg.get_srcSystem(), [])
            name = mavutil.mode_string_v10(msg)
            if not seen or seen[-1][1] != name:
                seen.append((stamp, name))
        elif kind == "STATUSTEXT":
            texts.setdefault(msg.get_srcSystem(), []).append((stamp, msg.severity, msg.text))
    conn.close()
    contexts = _contexts(path)
    if not contexts:
        pytest.skip("no battery records: the view yields no chunk")
    levels = ("emergency", "alert", "critical", "error", "warning", "notice", "info", "debug")
    for context in contexts:
        assert context.vehicle is not None
        sysid = int(context.vehicle.split(":")[1])
        assert context.start_us is not None
        first = context.start_us / 1e6  # t = 0: the tlog's first stamp
        assert [m for _, m in context.modes] == [m for _, m in modes.get(sysid, [])]
        assert [t for t, _ in context.modes] == pytest.approx([s - first for s, _ in modes.get(sysid, [])], abs=2e-6)
        theirs = texts.get(sysid, [])
        assert [(x.severity, x.text) for x in context.texts] == [(levels[v], text) for _, v, text in theirs]
        assert [x.t for x in context.texts] == pytest.approx([s - first for s, _, _ in theirs], abs=2e-6)
        banner = next((text for _, _, text in theirs if re.match(r"(Ardu\w+|APM:\w+) V\d", text)), None)
        assert context.firmware == banner  # ArduPilot's boot banner names the firmware and its version
    assert any(c.modes for c in contexts) or not any(modes.values())


@pytest.mark.parametrize("path", ULOGS, ids=[p.name for p in ULOGS])
def test_ulog_battery_failsafe_flags_match_pyulog(path: Path) -> None:
    """The report's markers of commander's battery failsafe inputs: each rise of ``failsafe_flags.battery_warning``
    and each time ``battery_low_remaining_time`` turns true, at pyulog's timestamps of the same records."""
    contexts = _contexts(path)
    if not contexts:
        pytest.skip("no battery records: the view yields no chunk")
    (context,) = contexts
    log = pyulog.ULog(str(path), ["failsafe_flags"])
    data = next((d.data for d in log.data_list if d.multi_id == 0), None)
    expected: list[tuple[float, str]] = []
    if data is not None:
        level, was_low = 0, False
        low = data.get("battery_low_remaining_time", np.zeros(len(data["timestamp"])))
        for stamp, warning, flag in zip(data["timestamp"], data["battery_warning"], low, strict=True):
            t = (int(stamp) - log.start_timestamp) / 1e6
            if int(warning) > level and int(warning) in (1, 2, 3):
                expected.append(
                    (t, f"battery warning {('LOW', 'CRITICAL', 'EMERGENCY')[int(warning) - 1]} (failsafe_flags)")
                )
            level = int(warning)
            if flag and not was_low:
                expected.append((t, "remaining flight time low (failsafe_flags)"))
            was_low = bool(flag)
    ours = [f for f in context.failsafes if "(failsafe_flags)" in f[1]]
    assert [w for _, w in ours] == [w for _, w in expected]
    assert [t for t, _ in ours] == pytest.approx([t for t, _ in expected], abs=1e-6)
