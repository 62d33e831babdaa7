"""The converters' C float-to-integer assignment takes its usual values (finite, inside 32 bits) by a shorter
path: on every boundary and a grid around them it gives what the general rule gives, and reports the same."""

from __future__ import annotations

import math

import pytest

from generated.convert import _runtime as r


def general(x: float, bits: int, signed: bool, rep: r.LossReport | None, label: str) -> int:
    """The rule as written before the shorter path: VCVT's saturation to 32 bits, then the field's low bits."""
    if math.isnan(x):
        n = 0
    elif signed:
        n = -(1 << 31) if x <= -(2.0**31) else (1 << 31) - 1 if x >= 2.0**31 else int(x)
    else:
        n = 0 if x <= 0 else (1 << 32) - 1 if x >= 2.0**32 else int(x)
    out = r.c_wrap(n, bits, signed)
    if rep is not None and not math.isnan(x) and out != (int(x) if math.isfinite(x) else None):
        rep.clamped(label, f"{x!r} does not fit {'int' if signed else 'uint'}{bits}")
    return out


EDGES = [0.0, -0.0, 0.5, -0.5, 0.99, -0.99, 1.0, -1.0, 127.5, 128.0, -128.5, 255.9, 256.0, 32767.0, 32768.0,
         -32768.0, -32769.0, 65535.0, 65536.0, 2.0**31 - 1, 2.0**31, -(2.0**31), -(2.0**31) - 1, 2.0**32 - 1,
         2.0**32, 1e20, -1e20, math.inf, -math.inf, math.nan, 3.4028234663852886e38]  # fmt: skip
VALUES = EDGES + [sign * (k * 997.25) for k in range(0, 3000, 7) for sign in (1, -1)]


@pytest.mark.parametrize("bits", [8, 16, 32])
@pytest.mark.parametrize("signed", [True, False])
def test_fast_path_is_the_general_rule(bits: int, signed: bool) -> None:
    for x in VALUES:
        ours, theirs = r.LossReport(), r.LossReport()
        assert r.c_float_to_int(x, bits, signed, ours, "f") == general(x, bits, signed, theirs, "f"), x
        assert ours.entries == theirs.entries, x
        assert r.c_float_to_int(x, bits, signed) == general(x, bits, signed, None, ""), x
