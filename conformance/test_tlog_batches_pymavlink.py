"""Every real tlog of ``../shared`` (told by content: ``dronekit-la_fs-batt.log`` is one) read through the battery
view (:mod:`codegen.apps.battery.tlog_batches`) and by pymavlink's own log reader (``mavutil.mavmmaplog``, which
``mavutil.mavlink_connection`` opens for a tlog) on the same file: per system and battery, the record count, first
and last ``t`` (seconds since the log's first message), minimum and maximum voltage, maximum current and armed time
(pymavlink's ``sysid_state[sysid].armed``, set by its own vehicle-heartbeat rule, as of each record) agree."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from shared_data import SHARED

from codegen.apps.battery.view import read_view
from codegen.inputs.files.kinds import detect


def _tlogs() -> list[Path]:
    if not SHARED.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"{SHARED} (the shared real logs) is missing")
        return []
    found = []
    for top in (SHARED / "corpus", SHARED / "data"):
        found.extend(p for p in sorted(top.rglob("*")) if p.is_file() and detect(p) == "tlog")
    return found


TLOGS = _tlogs()


@dataclass
class Figures:
    t: list[float] = field(default_factory=list)
    volts: list[float] = field(default_factory=list)
    amps: list[float] = field(default_factory=list)
    armed: list[bool] = field(default_factory=list)

    def summary(self) -> tuple[Any, ...]:
        dt = np.diff(np.array(self.t))
        armed_time = float(np.sum(dt[np.array(self.armed[:-1], bool)])) if len(self.t) > 1 else 0.0
        volts = [v for v in self.volts if not math.isnan(v)]
        amps = [a for a in self.amps if not math.isnan(a)]
        return (
            len(self.t),
            round(self.t[0], 6),
            round(self.t[-1], 6),
            round(min(volts), 6) if volts else None,
            round(max(volts), 6) if volts else None,
            round(max(amps), 6) if amps else None,
            round(armed_time, 6),
        )


def _pymavlink(path: Path, monkeypatch: pytest.MonkeyPatch) -> dict[tuple[str, int], tuple[Any, ...]]:
    monkeypatch.setenv("MAVLINK20", "1")  # its MAVLink 2 parser, which reads MAVLink 1 frames too
    from pymavlink import mavutil

    mavutil.set_dialect("ardupilotmega")
    conn = mavutil.mavmmaplog(str(path))
    # its index pass decodes (and posts) the first message of each type, so a HEARTBEAT from later in the log
    # would set the arming state before the first record: start the replay's state afresh
    conn.sysid_state = {}
    first: float | None = None
    battery: dict[tuple[int, int], Figures] = {}
    status: dict[int, Figures] = {}
    while (msg := conn.recv_match()) is not None:
        kind = msg.get_type()
        if kind == "BAD_DATA":
            continue
        first = msg._timestamp if first is None else first
        sysid = msg.get_srcSystem()
        if kind == "BATTERY_STATUS":
            cells = [v for v in msg.voltages if v != 65535] + [v for v in msg.voltages_ext if v != 0]
            volts = sum(cells) / 1000 if cells else math.nan
            amps = msg.current_battery / 100 if msg.current_battery != -1 else math.nan
            fig = battery.setdefault((sysid, msg.id), Figures())
        elif kind == "SYS_STATUS":
            volts = msg.voltage_battery / 1000 if msg.voltage_battery != 65535 else math.nan
            amps = msg.current_battery / 100 if msg.current_battery != -1 else math.nan
            fig = status.setdefault(sysid, Figures())
        else:
            continue
        assert first is not None
        fig.t.append(msg._timestamp - first)
        fig.volts.append(volts)
        fig.amps.append(amps)
        fig.armed.append(bool(conn.sysid_state[sysid].armed))
    conn.close()
    out = {(f"mavlink:{s}", b): fig.summary() for (s, b), fig in battery.items()}
    out.update({(f"mavlink:{s}", 0): fig.summary() for s, fig in status.items() if not any(k[0] == s for k in battery)})
    return out


def _ours(path: Path) -> dict[tuple[str, int], tuple[Any, ...]]:
    figures: dict[tuple[str, int], Figures] = {}
    for chunk in read_view(path):
        batch = chunk.batch
        assert isinstance(batch.vehicle, str)
        for b in np.unique(chunk.battery).tolist():
            rows = chunk.battery == b
            fig = figures.setdefault((batch.vehicle, b), Figures())
            fig.t.extend(batch.t[rows].tolist())
            fig.volts.extend(chunk.number("pack_voltage")[rows].tolist())
            fig.amps.extend(chunk.number("current")[rows].tolist())
            armed = np.zeros(batch.n) if batch.armed is None else np.nan_to_num(batch.armed)
            fig.armed.extend((armed[rows] == 1.0).tolist())
    return {k: fig.summary() for k, fig in figures.items()}


def test_the_shared_folder_holds_tlogs() -> None:
    if not SHARED.is_dir():
        pytest.skip("../shared is not present")
    assert any(p.suffix == ".log" for p in TLOGS)  # one recognised by its content, not its name
    assert len(TLOGS) >= 5


@pytest.mark.parametrize("path", TLOGS, ids=[p.relative_to(SHARED).as_posix() for p in TLOGS])
def test_battery_figures_equal_pymavlinks(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    theirs = _pymavlink(path, monkeypatch)
    ours = _ours(path)
    assert theirs, path
    for key in sorted(set(theirs) | set(ours)):
        assert ours.get(key) == pytest.approx(theirs.get(key), abs=1e-6), key
