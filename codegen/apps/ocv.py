"""State of charge from open-circuit voltage, bit-exact with the Linux power-supply core.

Facts kept from drivers/power/supply/power_supply_core.c and include/linux/fixp-arith.h:
- the table is the one whose ``ocv-capacity-celsius`` entry is nearest the temperature; on a tie
  the first (lowest index) wins, because only a strictly smaller distance replaces the best;
- tables are ordered by falling OCV; the lookup stops at the first entry whose OCV is below the
  measured one and interpolates between it and the entry before; above the first entry the
  first capacity is returned, at or below the last entry the last capacity (clamped ends);
- interpolation is ``y0 + (y1 - y0) * (x - x0) / (x1 - x0)`` in C ``int`` arithmetic: the
  division truncates toward zero, and the kernel builds with wrapping signed overflow;
- at most POWER_SUPPLY_OCV_TEMP_MAX (20) temperatures; table N is ``ocv-capacity-table-N``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

OCV_TEMP_MAX = 20
INT_MAX = (1 << 31) - 1

Table = Sequence[Sequence[int]]  # rows of (ocv in microvolts, capacity in percent)


def _s32(value: int) -> int:
    """Wrap to a C int (two's complement), as the kernel's arithmetic does."""
    value &= 0xFFFFFFFF
    return value - (1 << 32) if value & 0x80000000 else value


def _cdiv(a: int, b: int) -> int:
    """C integer division: truncates toward zero."""
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


def linear_interpolate(x0: int, y0: int, x1: int, y1: int, x: int) -> int:
    """fixp_linear_interpolate(): the exact-point and flat cases first, then the int formula."""
    if y0 == y1 or x == x0:
        return y0
    if x1 == x0 or x == x1:
        return y1
    product = _s32(_s32(y1 - y0) * _s32(x - x0))
    return _s32(y0 + _cdiv(product, _s32(x1 - x0)))


def ocv_to_capacity_in_table(table: Table, ocv_uv: int) -> int:
    """power_supply_ocv2cap_simple(): capacity percent for an OCV, from one table."""
    if not table:
        raise ValueError("an OCV table needs at least one (ocv, capacity) row")
    n = len(table)
    i = next((k for k in range(n) if ocv_uv > table[k][0]), n)
    if i == 0:
        low = high = 0
    elif i == n:
        low = high = n - 1
    else:
        low, high = i, i - 1
    return linear_interpolate(table[low][0], table[low][1], table[high][0], table[high][1], ocv_uv)


def find_table_index(temps_celsius: Sequence[int], temp_celsius: int) -> int:
    """power_supply_find_ocv2cap_table(): index of the nearest temperature, first one on a tie."""
    if not temps_celsius:
        raise ValueError("no ocv-capacity-celsius temperatures: expected at least one")
    best_diff, best = INT_MAX, 0
    for i, t in enumerate(temps_celsius[:OCV_TEMP_MAX]):
        diff = _s32(abs(_s32(t - temp_celsius)))  # C abs(INT_MIN) stays INT_MIN
        if diff < best_diff:
            best_diff, best = diff, i
    return best


def ocv_to_capacity(tables: Sequence[Table], temps_celsius: Sequence[int], ocv_uv: int, temp_celsius: int) -> int:
    """power_supply_batinfo_ocv2cap(): pick the table for the temperature, then look the OCV up.

    ``tables[i]`` belongs to ``temps_celsius[i]``; like power_supply_get_battery_info() this
    refuses more than 20 temperatures and a temperature without a (non-empty) table.
    """
    if len(temps_celsius) > OCV_TEMP_MAX:
        raise ValueError(f"{len(temps_celsius)} OCV temperatures: the kernel accepts at most {OCV_TEMP_MAX}")
    if len(tables) < len(temps_celsius):
        raise ValueError(f"{len(temps_celsius)} OCV temperatures but {len(tables)} tables: expected one table each")
    for i in range(len(temps_celsius)):
        if not tables[i]:
            raise ValueError(f"ocv-capacity-table-{i} is empty: expected (ocv, capacity) rows")
    index = find_table_index(temps_celsius, temp_celsius)
    return ocv_to_capacity_in_table(tables[index], ocv_uv)


def tables_from_properties(props: Mapping[str, Any]) -> tuple[list[Table], list[int]]:
    """(tables, temperatures) from a simple-battery dict as node_to_model_dict / to_dict give it:
    ``ocv-capacity-celsius`` and ``ocv-capacity-table-0..N-1``; values are wrapped to C ints as
    the kernel reads the u32 cells into ints."""
    temps = [_s32(int(t)) for t in props.get("ocv-capacity-celsius") or []]
    tables: list[Table] = []
    for i in range(len(temps)):
        rows = props.get(f"ocv-capacity-table-{i}")
        if not rows:
            raise ValueError(f"ocv-capacity-table-{i} is missing: expected one table per ocv-capacity-celsius entry")
        tables.append([(_s32(int(r[0])), _s32(int(r[1]))) for r in rows if len(r) >= 2])  # kernel drops a half row
    return tables, temps
