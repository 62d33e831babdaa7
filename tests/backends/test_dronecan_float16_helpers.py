"""The float16 helpers the generated DroneCAN encoders call (generated/_dronecan.py): the casts before
rounding, and the rounding the encoders inline for a positive normal half and leave to ``f16bits``
otherwise -- both against pydronecan's libuavcan-derived ``f16_from_f32`` on the same values."""

from __future__ import annotations

import math
import struct

from dronecan.transport import f16_from_f32
from hypothesis import given, settings
from hypothesis import strategies as st

from generated import _dronecan as dc

F16_MAX = 65504.0


def _f32_bits(x: float) -> int:
    return int(struct.unpack("<I", struct.pack("<f", x))[0])


def _encoder_half(x: float) -> int:
    """What a generated encoder computes for a saturated float16 field (segments.float16_batch)."""
    value = x if -F16_MAX <= x <= F16_MAX else dc.f16_saturated(x)
    g = _f32_bits(value)
    return ((g - 0x37FFF000) >> 13) if 0x38800000 <= g < 0x477FF000 else dc.f16bits(g)


def test_casts_before_rounding() -> None:
    assert dc.f16_saturated(1e6) == F16_MAX and dc.f16_saturated(-1e6) == -F16_MAX
    assert dc.f16_saturated(math.inf) == math.inf and dc.f16_saturated(-math.inf) == -math.inf
    assert math.isnan(dc.f16_saturated(math.nan)) and dc.f16_saturated(12.5) == 12.5
    assert dc.f16_truncated(65505.0) == math.inf and dc.f16_truncated(-1e6) == -math.inf
    assert math.isnan(dc.f16_truncated(math.nan)) and dc.f16_truncated(-F16_MAX) == -F16_MAX


@settings(max_examples=400, deadline=None)
@given(st.floats(width=32, allow_nan=False, allow_infinity=False, min_value=-F16_MAX, max_value=F16_MAX))
def test_encoder_rounding_agrees_with_pydronecan(x: float) -> None:
    assert _encoder_half(x) == f16_from_f32(x) == dc.f16s(x)


def test_edges_agree_with_pydronecan() -> None:
    edges = [0.0, -0.0, 6.1035156e-05, 6.09e-05, 5.96e-08, 2049.0, -2049.0, 65504.0, -65504.0, 1.0, -1.0]
    for x in edges:
        assert _encoder_half(x) == f16_from_f32(x), x
    assert _encoder_half(1e6) == 0x7BFF and _encoder_half(-1e6) == 0xFBFF  # saturated to +-65504
    assert _encoder_half(math.inf) == 0x7C00 and _encoder_half(math.nan) == 0x7FFF
