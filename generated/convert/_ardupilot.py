# Copied by battgen from codegen/backends/python/runtime/convert/_ardupilot.py; do not edit here, edit it there.
"""Run-time support of the generated converters: ArduPilot's battery arithmetic for the ``ardupilot``
policy, as its DroneCAN battery monitor (``AP_BattMonitor_DroneCAN``), the battery backend
(``AP_BattMonitor_Backend``) and ``GCS_MAVLINK::send_battery_status`` compute BATTERY_STATUS from a
DroneCAN battery: float32 where the firmware holds a float, C's float-to-integer conversions as a
Cortex-M FPU performs them (:func:`~._runtime.c_float_to_int`), and AP_Math's own ``MIN`` and
``constrain`` (which differ from Python's on NaN).

Standard library only: this file is copied verbatim into ``generated/convert/_ardupilot.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ._runtime import LossReport, c_float_to_int, c_wrap, f32, f32_div

AUS_TO_MAH = f32(0.0000002778)  # AP_Math: ampere-microseconds to milliampere-hours, a float constant
FLT_EPSILON = 2.0**-23  # is_zero(x) is fabsf(x) < FLT_EPSILON
UINT16_MAX = 0xFFFF  # a cell BATTERY_STATUS does not report
MAX_CELL_MV = 0xFFFE  # the most one cell field carries
IGNORE_CAN_SOC = 1  # BATT_OPTIONS bit 0 (Ignore_UAVCAN_SoC)
SOC_UNKNOWN = 127  # BatteryInfo's state_of_charge_pct that ArduPilot takes as "no state of charge"
INTEGRATE_BELOW_US = 2_000_000  # update_consumed skips a gap of 2 s or more


def ap_min(a: float, b: float) -> float:
    """AP_Math's ``MIN(a, b)``: ``a < b ? a : b``, so a NaN ``a`` gives ``b``."""
    return a if a < b else b


def constrain(x: float, lo: float, hi: float) -> float:
    """AP_Math's ``constrain_float``: NaN becomes the middle of the range (0 for a symmetric one)."""
    if math.isnan(x):
        return (lo + hi) / 2
    return lo if x < lo else hi if x > hi else x


def _whole(value: float | None) -> int:
    """A parameter given as a number, as the integer ArduPilot stores it (0 when absent or not finite)."""
    return int(value) if value is not None and math.isfinite(value) else 0


def ardupilot_cells(
    voltage: float,
    aux_cells: Sequence[float] | None,
    max_cells: int,
    n_main: int,
    n_ext: int,
    rep: LossReport | None,
    label: str,
) -> tuple[list[int], list[int]]:
    """``send_battery_status``'s two cell arrays (mV) from the pack voltage (V) and, when a
    BatteryInfoAux came, its cells (V; ``handle_battery_info_aux`` keeps at most ``max_cells``, the
    firmware's AP_BATT_MONITOR_CELLS_MAX)."""
    volt_mv = f32(f32(voltage) * 1000.0)  # battery.gcs_voltage(instance) * 1e3f
    if aux_cells is None:  # no cell voltages: the pack voltage over the cell fields
        main: list[int] = []
        for _ in range(n_main):
            if volt_mv < f32(0.001):
                main.append(UINT16_MAX)
            else:
                main.append(c_float_to_int(ap_min(volt_mv, float(MAX_CELL_MV)), 16, False, rep, label))
                volt_mv = f32(volt_mv - MAX_CELL_MV)
        return main, [0] * n_ext
    cells = [0] * max_cells  # a new monitor's cells are zero until a message fills them
    for i in range(min(len(aux_cells), max_cells)):
        cells[i] = c_float_to_int(f32(f32(aux_cells[i]) * 1000.0), 16, False, rep, label)
    main = cells[:n_main]
    ext = [cells[n_main + i] if n_main + i < max_cells else 0 for i in range(n_ext)]
    # the pack voltage above the cells' sum is shared out over the cells that report
    total = 0.0
    count = 0
    for v in (*main, *ext):
        if 0 < v != UINT16_MAX:
            count += 1
            total = f32(total + v)
    if volt_mv > total and count > 0:
        extra = c_float_to_int(f32(f32(volt_mv - total) / count), 32, False)
        main = [min(v + extra, MAX_CELL_MV) if 0 < v != UINT16_MAX else v for v in main]
        ext = [min(v + extra, MAX_CELL_MV) if 0 < v != UINT16_MAX else v for v in ext]
    return main, ext


def ardupilot_estimates(
    voltage: float,
    current_a: float,
    soc: int,
    remaining_wh: float,
    full_wh: float,
    nominal_v: float | None,
    inputs: tuple[float | None, float | None, float | None, float | None, float | None, float | None],
    rep: LossReport | None,
    labels: tuple[str, str, str, str],
) -> tuple[int, int, int, int]:
    """BATTERY_STATUS's (current_consumed mAh, energy_consumed hJ, battery_remaining %, time_remaining s)
    after one BatteryInfo (and, when ``nominal_v`` is not None, a BatteryInfoAux of the same battery).

    ``inputs`` are (seconds since the previous BatteryInfo or None for the first, consumed mAh and Wh so
    far, BATT_CAPACITY mAh, BATT_OPTIONS, BATT_CURR_MULT), None where the caller has none."""
    dt_s, mah_before, wh_before, capacity, options, curr_mult = inputs
    has_aux = nominal_v is not None
    amps = f32(f32(1.0 if curr_mult is None else curr_mult) * f32(current_a))  # _curr_mult * current
    use_soc = not (_whole(options) & IGNORE_CAN_SOC) and soc != SOC_UNKNOWN  # use_CAN_SoC()
    mah = f32(mah_before or 0.0)
    wh = f32(wh_before or 0.0)
    # update_interim_state: count charge unless a BatteryInfoAux came and the battery's SoC is used
    if (not has_aux or not use_soc) and dt_s is not None and math.isfinite(dt_s):
        dt_us = c_wrap(int(dt_s * 1e6), 32, False)  # tnow - last_time_micros, uint32_t
        if dt_us < INTEGRATE_BELOW_US:
            step = f32(f32(amps * f32(dt_us)) * AUS_TO_MAH)  # calculate_mah(current_amps, dt_us)
            mah = f32(mah + step)
            wh = f32(wh + 0.001 * step * f32(voltage))  # 0.001 is a double: the sum is one, stored as float
    time_s = 0  # time_remaining() is false until a BatteryInfoAux gave a nominal voltage
    if nominal_v is not None and nominal_v > 0:  # handle_battery_info_aux (NaN > 0 is false)
        remaining_ah = f32_div(f32(remaining_wh), f32(nominal_v))
        full_ah = f32_div(f32(full_wh), f32(nominal_v))
        mah = f32(f32(full_ah - remaining_ah) * 1000.0)
        wh = f32(f32(full_wh) - f32(remaining_wh))
        seconds = 0.0 if abs(amps) < FLT_EPSILON else f32(f32_div(remaining_ah, amps) * 3600.0)
        time_s = c_wrap(c_float_to_int(seconds, 32, False), 32, True)  # uint32_t, sent as int32_t
    # capacity_remaining_pct, then GCS_MAVLINK::battery_remaining_pct and constrain_int16(pct, -1, 100)
    percent: int | None = soc
    if not use_soc:
        pack = _whole(capacity)
        if pack <= 10:
            percent = None
        else:
            left = f32(pack - mah)
            percent = c_float_to_int(constrain(f32_div(f32(100.0 * left), f32(pack)), 0.0, 255.0), 8, False)
    remaining = -1 if percent is None else max(-1, min(min(percent, 127), 100))
    if rep is not None:  # the float totals the monitor keeps for its next message
        rep.carry("consumed_mah", mah)
        rep.carry("consumed_wh", wh)
    consumed = c_float_to_int(mah, 32, True, rep, labels[0])
    energy = c_float_to_int(f32(wh * 36.0), 32, True, rep, labels[1])  # consumed_wh *= 36: hJ
    return consumed, energy, remaining, time_s
