"""A log's context (:mod:`codegen.apps.battery.context`) from odd parameter values: NaN, the infinities and an int32
beyond float32's precision read as the log holds them, in a ULog and in a tlog, never a traceback."""

from __future__ import annotations

import math
import struct
from pathlib import Path

from codegen.apps.battery.view import read_view
from codegen.cli.main import main
from generated import _ulog_writer
from generated.uorb import BatteryStatus


def test_ulog_parameters_keep_nan_infinity_and_int32(tmp_path: Path) -> None:
    path = tmp_path / "odd.ulg"
    params = {"BAT_LOW_THR": math.nan, "BAT_CRIT_THR": math.inf, "BAT1_N_CELLS": 16_777_217, "BAT1_R_INTERNAL": 0.005}
    with _ulog_writer.Writer(path, parameters=params, messages=[BatteryStatus]) as w:
        w.write(BatteryStatus(timestamp=1000, voltage_v=12.0, max_error=1))
    (chunk,) = list(read_view(path))
    got = chunk.batch.context.parameters if chunk.batch.context is not None else {}
    assert math.isnan(got["BAT_LOW_THR"]) and got["BAT_CRIT_THR"] == math.inf
    assert got["BAT1_N_CELLS"] == 16_777_217.0  # an int32, not rounded to a float32
    assert got["BAT1_R_INTERNAL"] == 0.005  # the float32 0.004999999888241291, as a person reads it
    assert main(["report", "--format", "json", "-o", str(tmp_path / "r.json"), str(path)]) == 0


def test_tlog_parameter_values_keep_nan_and_infinity(tmp_path: Path) -> None:
    from pymavlink.dialects.v20 import common

    mav = common.MAVLink(None, srcSystem=1, srcComponent=1)
    stamp = struct.pack(">Q", 1_700_000_000_000_000)
    out = stamp + mav.heartbeat_encode(common.MAV_TYPE_QUADROTOR, common.MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 0, 4).pack(mav)
    for k, (name, value) in enumerate({"BATT_LOW_VOLT": math.inf, "BATT_CRT_VOLT": math.nan, "X": 10.6}.items()):
        out += stamp + mav.param_value_encode(name.encode(), value, common.MAV_PARAM_TYPE_REAL32, 3, k).pack(mav)
    out += stamp + mav.sys_status_encode(0, 0, 0, 0, 12000, 100, 50, 0, 0, 0, 0, 0, 0).pack(mav)
    path = tmp_path / "odd.tlog"
    path.write_bytes(out)
    (chunk,) = list(read_view(path))
    got = chunk.batch.context.parameters if chunk.batch.context is not None else {}
    assert got["BATT_LOW_VOLT"] == math.inf and math.isnan(got["BATT_CRT_VOLT"]) and got["X"] == 10.6
