"""The converters' OCV lookup (generated/convert/_cells.py, ``ocv_to_capacity``) against values worked
out by hand from the Linux power-supply core's integer arithmetic (power_supply_core.c, fixp-arith.h).

Tables are the battery.yaml example's: -10 degC (4185000,100) (4113000,95) (4066000,90);
0 degC (4200000,100) (4185000,95) (4113000,90); 10 degC (4250000,100) (4200000,95) (4185000,90).
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from generated.convert._cells import ocv_to_capacity


def ocv_to_capacity_in_table(table: Sequence[tuple[int, int]], ocv_uv: int) -> int:
    """One table alone: power_supply_ocv2cap_simple()."""
    return ocv_to_capacity([table], [0], ocv_uv, 0)


def linear_interpolate(x0: int, y0: int, x1: int, y1: int, x: int) -> int:
    """fixp_linear_interpolate() through the lookup: x between the two rows of a falling table
    (x0 the lower OCV, as the kernel passes it)."""
    return ocv_to_capacity_in_table([(x1, y1), (x0, y0)], x) if x1 > x0 else ocv_to_capacity_in_table([(x0, y0)], x)


def find_table_index(temps_celsius: Sequence[int], temp_celsius: int) -> int:
    """power_supply_find_ocv2cap_table() through the lookup: table i holds capacity i alone."""
    return ocv_to_capacity([[(0, i)] for i in range(len(temps_celsius))], temps_celsius, 0, temp_celsius)


COLD = [(4185000, 100), (4113000, 95), (4066000, 90)]
ZERO = [(4200000, 100), (4185000, 95), (4113000, 90)]
WARM = [(4250000, 100), (4200000, 95), (4185000, 90)]
TEMPS = [-10, 0, 10]


@pytest.mark.parametrize(
    ("ocv", "expected", "why"),
    [
        (4300000, 100, "above the first entry: clamped to the first capacity"),
        (4185001, 100, "just above the first entry"),
        (4185000, 100, "exact first point: stops at i=1, x == x1 returns y1"),
        (4150000, 97, "95 + 5*37000/72000 = 95 + 2 (2.57 truncated)"),
        (4113000, 95, "exact middle point: i=2, x == x1"),
        (4100000, 93, "90 + 5*34000/47000 = 90 + 3 (3.62 truncated)"),
        (4070000, 90, "90 + 5*4000/47000 = 90 + 0"),
        (4066000, 90, "exact last point: no entry below, i == len, clamped"),
        (3000000, 90, "below the table: clamped to the last capacity"),
        (-5, 90, "a negative OCV is just below the table"),
    ],
)
def test_ocv_to_capacity_in_table(ocv: int, expected: int, why: str) -> None:
    assert ocv_to_capacity_in_table(COLD, ocv) == expected, why


def test_division_truncates_toward_zero() -> None:
    # Capacity rising as OCV falls (a malformed but readable table): the product is negative.
    # 20 + (10 - 20) * (3933 - 3900) / (4000 - 3900) = 20 + (-330 / 100) = 20 - 3 in C (floor: -4).
    assert ocv_to_capacity_in_table([(4000, 10), (3900, 20)], 3933) == 17


def test_int_overflow_wraps_like_the_kernel() -> None:
    # (100000 - 0) * (500000 - 0) = 5e10 wraps to -1539607552 in a 32-bit int; / 1000000 -> -1539.
    assert linear_interpolate(0, 0, 1000000, 100000, 500000) == -1539


def test_interpolate_shortcuts() -> None:
    assert linear_interpolate(1, 7, 5, 7, 3) == 7  # flat segment
    assert linear_interpolate(0, 0, 10, 100, 10) == 100  # exactly on the upper row


def test_single_row_table() -> None:
    assert ocv_to_capacity_in_table([(3700000, 40)], 4000000) == 40
    assert ocv_to_capacity_in_table([(3700000, 40)], 3000000) == 40


@pytest.mark.parametrize(
    ("temp", "index"),
    [
        (-100, 0),
        (-10, 0),
        (-5, 0),  # tie between -10 and 0 (both 5 away): the first table wins
        (-4, 1),
        (4, 1),
        (5, 1),  # tie between 0 and 10: the first of the two wins
        (6, 2),
        (100, 2),
    ],
)
def test_find_table_index(temp: int, index: int) -> None:
    assert find_table_index(TEMPS, temp) == index


def test_duplicate_temperatures_pick_the_first() -> None:
    assert find_table_index([20, 20, 25], 21) == 0


def test_only_twenty_temperatures_count() -> None:
    temps = [100] * 20 + [0]
    assert find_table_index(temps, 0) == 0  # the 21st entry is beyond POWER_SUPPLY_OCV_TEMP_MAX


def test_ocv_to_capacity_picks_then_interpolates() -> None:
    tables = [COLD, ZERO, WARM]
    # 5 degC ties 0 and 10: the 0 degC table; 90 + 5*37000/72000 = 92.
    assert ocv_to_capacity(tables, TEMPS, 4150000, 5) == 92
    # 8 degC: the 10 degC table; 4150000 is below it: clamped to 90.
    assert ocv_to_capacity(tables, TEMPS, 4150000, 8) == 90
    # -30 degC: the -10 degC table.
    assert ocv_to_capacity(tables, TEMPS, 4150000, -30) == 97
