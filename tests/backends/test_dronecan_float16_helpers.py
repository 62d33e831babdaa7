"""The float16 helpers the generated DroneCAN encoders call (generated/_dronecan.py): the float32 bits of a
run of float16 fields (``float32_bits``), the casts before rounding, and the rounding the encoders inline for
a positive normal half and leave to ``f16bits_saturated`` / ``f16bits`` otherwise -- against pydronecan's
libuavcan-derived ``f16_from_f32`` on the same values."""

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
    (g,) = dc.float32_bits(1)(x)
    return ((g - 0x37FFF000) >> 13) if 0x38800000 <= g < 0x477FF000 else dc.f16bits_saturated(g)


def _truncated_half(x: float) -> int:
    """The same for a truncated float16 field beside a saturated one (the cast runs before packing)."""
    g = dc.float32_bits(2, truncated=(1,))(0.0, x)[1]
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
    # beyond +-65504 the cut clamps what float32_bits left as it was; beyond float32 float32_bits clamps itself
    assert _encoder_half(65519.0) == _encoder_half(65520.0) == _encoder_half(1e300) == 0x7BFF
    assert _encoder_half(-65520.0) == _encoder_half(-1e300) == 0xFBFF


@settings(max_examples=300, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True))
def test_float32_bits_and_cut_agree_with_the_one_call_casts(x: float) -> None:
    assert _encoder_half(x) == dc.f16s(x)
    assert _truncated_half(x) == dc.f16t(x)


def test_truncated_beyond_the_range_is_infinity() -> None:
    assert _truncated_half(65505.0) == 0x7C00 and _truncated_half(-1e300) == 0xFC00
    assert _truncated_half(65504.0) == 0x7BFF
