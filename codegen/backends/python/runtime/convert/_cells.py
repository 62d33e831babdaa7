"""Run-time support of the generated converters: the array algorithms the mappings name (cells up
to a marker, MAVLink cell packing, PX4's own cell paths, the Linux OCV table lookup).

Standard library only: this file is copied verbatim into ``generated/convert/_cells.py``.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Sequence
from typing import Any

from ._runtime import LossReport, c_div, c_float_to_int, f32, is_marker, to_int


def leading(values: Sequence[float], marker: float | None) -> list[float]:
    """The values before the first ``marker`` (all of them when there is none)."""
    out: list[float] = []
    for v in values:
        if marker is not None and is_marker(v, marker):
            break
        out.append(v)
    return out


def dt_first(value: Any) -> Any:
    """The first scalar of a devicetree property (``<3200000>`` is ``[[3200000]]``), or None."""
    while isinstance(value, list | tuple):
        if not value:
            return None
        value = value[0]
    return value


def mavlink_cells_in(
    main: Sequence[int], ext: Sequence[int], main_marker: int, ext_marker: int, spill: int
) -> tuple[list[int] | None, int | None]:
    """(cells, pack) from BATTERY_STATUS voltages: cells up to the first marker, the extension
    cells only when all main cells are used; a lone value or a spill (``spill`` in the first
    cell) is the pack voltage with cells unknown."""
    cells = leading(main, main_marker)
    if len(cells) == len(main):
        cells += leading(ext, ext_marker)
    if not cells:
        return None, None
    ints = [int(c) for c in cells]
    if len(ints) == 1 or ints[0] == spill:
        return None, sum(ints)
    return ints, sum(ints)


def mavlink_cells_out(
    cells: Sequence[float] | None,
    pack: float | None,
    n_main: int,
    n_ext: int,
    main_marker: int,
    ext_marker: int,
    rep: LossReport | None,
    label_main: str,
    label_ext: str,
) -> tuple[list[int], list[int]]:
    """BATTERY_STATUS voltages from cells (in mV), else from the pack voltage (mV) spilled in
    ``main_marker - 1`` chunks; a measured 0 in the extension cells is sent as 1."""
    main = [main_marker] * n_main
    ext = [ext_marker] * n_ext
    top = main_marker - 1
    if cells and all(math.isnan(c) for c in cells):
        cells = None  # a cell count without cell voltages: the pack voltage goes in, as MAVLink asks
    if cells:
        if len(cells) > n_main + n_ext:
            if rep is not None:
                rep.clamped(label_ext, f"{len(cells)} cells, room for {n_main} + {n_ext}")
            cells = cells[: n_main + n_ext]
        for i, c in enumerate(cells):
            label, marker = (label_main, main_marker) if i < n_main else (label_ext, ext_marker)
            if math.isnan(c):  # one cell unknown among known ones: MAVLink has only "no cell" for it
                value = marker
                if rep is not None:
                    rep.unrepresentable(label, f"cell {i + 1} unknown (NaN), sent as {marker} (no cell)")
            elif i < n_main:
                value = to_int(c, 0, top, rep, label)
            else:
                value = max(to_int(c, 0, top, rep, label), 1 if ext_marker == 0 else 0)
            if i < n_main:
                main[i] = value
            else:
                ext[i - n_main] = value
        return main, ext
    if pack is not None and not math.isnan(pack):
        mv = to_int(pack, 0, top * n_main, rep, label_main)
        i = 0
        while mv > top and i < n_main - 1:
            main[i] = top
            mv -= top
            i += 1
        main[i] = mv
    elif rep is not None:
        rep.unknown(label_main)
    return main, ext


def px4_stream_cells(
    voltage_v: float,
    cells: Sequence[float],
    cell_count: int,
    connected: bool,
    mul: float,
    threshold: float,
    n_main: int,
    n_ext: int,
    main_fill: int,
    ext_fill: int,
    rep: LossReport | None,
    label: str,
) -> tuple[list[int], list[int]]:
    """PX4's BATTERY_STATUS cell fill (see the mapping's doc), float32 throughout."""
    main = [main_fill] * n_main
    ext = [ext_fill] * n_ext
    if not connected:
        return main, ext
    chunk = main_fill - 1
    if cell_count == 0 or f32(cells[0]) < threshold:
        total = f32(f32(voltage_v) * mul)
        fields = c_div(c_float_to_int(total, 32, True), chunk) + 1
        if 1 <= fields <= n_main:
            rest = total
            for i in range(fields - 1):
                main[i] = chunk
                rest = f32(rest - chunk)
            main[fields - 1] = c_float_to_int(rest, 16, False, rep, label)
        elif rep is not None:
            rep.clamped(label, f"pack voltage needs {fields} fields")
        return main, ext
    slots = min(cell_count, len(cells), n_main + n_ext)
    for i in range(slots):
        v = c_float_to_int(f32(f32(cells[i]) * mul), 16, False, rep, label)
        if i < n_main:
            main[i] = v
        else:
            ext[i - n_main] = v
    return main, ext


def px4_receiver_cells(
    voltages: Sequence[int], n_cells: int, marker: int, div: float
) -> tuple[list[float], int, float]:
    """PX4's receiver: cells while below ``marker`` (at most len(voltages)), v / div in float32, summed."""
    n = 0
    limit = min(len(voltages), n_cells)
    while n < limit and voltages[n] < marker:
        n += 1
    # float32 rounding of every quotient at once (an array('f') store is the C cast f32 makes)
    cells = array("f", [float(v) / div for v in voltages[:n]]).tolist() + [0.0] * (n_cells - n)
    acc = array("f", b"\0\0\0\0")
    for c in cells[:n]:
        acc[0] = acc[0] + c  # the running sum is rounded at each step, as in C
    return cells, n, acc[0]


# -- devicetree -----------------------------------------------------------------------------


def cells_from_design(
    vmax: float | None, vmin: float | None, chemistry: str | None, charged: dict[str, float], empty: dict[str, float]
) -> int | None:
    """Cells in series from a design voltage and the chemistry's cell voltage (nearest whole)."""
    if chemistry is None:
        return None
    for volts, table in ((vmax, charged), (vmin, empty)):
        per_cell = table.get(chemistry)
        if volts is not None and per_cell:
            n = math.floor(volts / per_cell + 0.5)
            if n >= 1:
                return n
    return None


def _s32(value: int) -> int:
    """Wrap to a C int, as the kernel's arithmetic does."""
    value &= 0xFFFFFFFF
    return value - (1 << 32) if value & 0x80000000 else value


def ocv_to_capacity(
    tables: Sequence[Sequence[Sequence[int]]], temps_celsius: Sequence[int], ocv_uv: int, temp_celsius: int
) -> int:
    """Capacity percent for an open-circuit voltage, as the Linux power-supply core computes it:
    the table of the nearest temperature (first on a tie, at most 20 looked at), then C ``int``
    linear interpolation between the points around ``ocv_uv`` (tables run from high to low
    voltage), clamped at the ends."""
    best, best_diff = 0, (1 << 31) - 1
    for i, t in enumerate(temps_celsius[: min(len(tables), 20)]):
        diff = _s32(abs(_s32(t - temp_celsius)))
        if diff < best_diff:
            best, best_diff = i, diff
    table = tables[best]
    i = 0
    while i < len(table) and not ocv_uv > table[i][0]:
        i += 1
    if i == 0:
        high = low = 0
    elif i == len(table):
        high = low = i - 1
    else:
        low, high = i, i - 1
    x0, y0 = table[low][0], table[low][1]
    x1, y1 = table[high][0], table[high][1]
    if y0 == y1 or ocv_uv == x0:
        return y0
    if x1 == x0 or ocv_uv == x1:
        return y1
    return _s32(y0 + c_div(_s32(_s32(y1 - y0) * _s32(ocv_uv - x0)), _s32(x1 - x0)))
