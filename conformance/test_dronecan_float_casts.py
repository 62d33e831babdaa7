"""DroneCAN float casts (DSDL v0 ``saturated`` / ``truncated``) against pydronecan, value by value.

A small DSDL type holds a float16, float32 and float64 field in each cast mode; it is generated into
a temporary package and parsed by pydronecan. Two paths are compared:

* bytes: pydronecan decodes a payload and re-encodes it; ours decodes it and encodes the object. The
  values read must be equal and so must the bytes written (NaN aside: pydronecan keeps the exact NaN
  bits it read, ours writes the canonical quiet NaN, as pydronecan's own converter does for a NaN value).
* values: the same value set on both objects encodes to the same bytes, for +-inf, NaN, +-65504, 65520,
  values between 65504 and 65520, subnormals, halfway cases and -0.0.

Where pydronecan disagrees with itself, the DSDL v0 specification decides: "saturated ... 65536.0 will
be converted to a float16 as 65504.0; infinity will be preserved" (dronecan/specification, section 3,
cast mode), as libuavcan's ``FloatSpec::saturate`` does (it leaves non-finite values alone) and as
pydronecan re-encodes a decoded infinity. Only pydronecan's value setter clamps infinity in saturated
mode (``cast`` compares inf > 65504); ``test_pydronecan_setter_clamps_infinity`` pins that one divergence.
"""

from __future__ import annotations

import importlib
import math
import struct
import sys
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from codegen.backends.python import naming
from codegen.backends.python.writer import generate
from codegen.frontends import dsdl

dronecan = pytest.importorskip("dronecan")
from dronecan import dsdl as pydsdl  # noqa: E402
from dronecan import transport  # noqa: E402

DSDL = """\
float16 s16
truncated float16 t16
float32 s32
truncated float32 t32
float64 s64
truncated float64 t64
"""
FIELDS = ("s16", "t16", "s32", "t32", "s64", "t64")
OFFSETS = {"s16": (0, 2), "t16": (2, 4), "s32": (4, 8), "t32": (8, 12), "s64": (12, 20), "t64": (20, 28)}
ZERO = bytes(28)

# the values the issue names, and their neighbours: the largest half, 65520 (where rounding would reach
# infinity; both casts act before rounding), values between, the smallest normal and subnormal halves
# and halfway cases
EDGES = [
    math.inf,
    -math.inf,
    math.nan,
    -math.nan,
    65504.0,
    -65504.0,
    65505.0,
    65519.99,
    -65519.99,
    65520.0,
    -65520.0,
    1e6,
    3.4028234663852886e38,
    3.5e38,
    -3.5e38,
    1e300,
    6.103515625e-05,  # smallest normal half
    6.1e-05,  # a subnormal half
    5.960464477539063e-08,  # smallest subnormal half
    2.9802322387695312e-08,  # half of it: the reference rounds a tie up (IEEE would give zero)
    2.9802325e-08,  # just above half of it: the smallest subnormal
    2.98e-08,  # just below half of it: zero
    -5.960464477539063e-08,
    1e-9,
    1.00048828125,  # halfway between two halves: rounded away from zero (struct's "e" rounds to even)
    1.0,
    -0.0,
    0.0,
]


@pytest.fixture(scope="module")
def types(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Any, Any]]:
    """(our generated class, pydronecan's type) of ``casts.Floats``."""
    root = tmp_path_factory.mktemp("dsdl_casts")
    (root / "casts").mkdir()
    (root / "casts" / "20999.Floats.uavcan").write_text(DSDL)
    out = tmp_path_factory.mktemp("casts_pkg")
    generate(dsdl.parse_dir(root), out / "dc_casts")
    sys.path.insert(0, str(out))
    try:
        schema = dsdl.parse_dir(root)
        (msg,) = schema.messages
        module = importlib.import_module(f"dc_casts.{naming.module_path(msg)}")
        ref = {t.full_name: t for t in pydsdl.parse_namespaces([str(root / "casts")])}["casts.Floats"]
        yield getattr(module, naming.class_name(msg)), ref
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] == "dc_casts"]:
            del sys.modules[name]


def _same(a: float, b: float) -> bool:
    """Equal values, NaN equal to NaN, and the sign of zero kept."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def ref_encode(ref: Any, values: dict[str, float]) -> bytes:
    obj = transport.CompoundValue(ref, _mode=None)
    for name, value in values.items():
        setattr(obj, name, value)
    return bytes(transport.bytes_from_bits(obj._pack(True)))


def ref_decode(ref: Any, data: bytes) -> Any:
    obj = transport.CompoundValue(ref, _mode=None)
    obj._unpack(transport.bits_from_bytes(data), True)
    return obj


def field_bytes(data: bytes, name: str) -> bytes:
    lo, hi = OFFSETS[name]
    return data[lo:hi]


def is_nan_field(data: bytes, name: str) -> bool:
    raw = field_bytes(data, name)
    code = {2: "<e", 4: "<f", 8: "<d"}[len(raw)]
    return math.isnan(struct.unpack(code, raw)[0])


@pytest.mark.parametrize("value", EDGES, ids=repr)
def test_values_encode_as_pydronecan_sets_them(types: tuple[Any, Any], value: float) -> None:
    """Every field, both cast modes: our bytes are pydronecan's for the same value (bar saturated infinity)."""
    ours_cls, ref = types
    for name in FIELDS:
        ours = ours_cls(**{name: value}).encode()
        expected = ref_encode(ref, {name: value})
        want = field_bytes(expected, name)
        if math.isinf(value) and name.startswith("s"):
            # pydronecan's setter clamps; the spec keeps infinity, written as the truncated twin writes it
            twin = "t" + name[1:]
            want = field_bytes(ref_encode(ref, {twin: value}), twin)
        else:
            assert ours == expected, (name, value)
        assert field_bytes(ours, name) == want, (name, value)
        # and both decoders read our bytes to the same value
        assert _same(getattr(ours_cls.decode(ours), name), getattr(ref_decode(ref, ours), name)), (name, value)


def test_pydronecan_setter_clamps_infinity(types: tuple[Any, Any]) -> None:
    """The one divergence, pinned: pydronecan's saturated setter writes +-max for +-inf, ours keeps infinity
    (the spec's rule), and pydronecan reads our bytes as infinity and re-encodes them unchanged."""
    ours_cls, ref = types
    for sign in (1.0, -1.0):
        value = sign * math.inf
        clamped = ref_encode(ref, {"s16": value, "s32": value, "s64": value})
        assert struct.unpack_from("<e", clamped, 0)[0] == sign * 65504.0
        assert struct.unpack_from("<f", clamped, 4)[0] == sign * 3.4028234663852886e38
        assert struct.unpack_from("<d", clamped, 12)[0] == sign * sys.float_info.max
        ours = ours_cls(s16=value, s32=value, s64=value).encode()
        decoded = ref_decode(ref, ours)
        assert (decoded.s16, decoded.s32, decoded.s64) == (value, value, value)
        assert bytes(transport.bytes_from_bits(decoded._pack(True))) == ours


def _check_bytes(ours_cls: Any, ref: Any, data: bytes) -> None:
    """pydronecan's decode and re-encode against ours on one payload."""
    ref_obj = ref_decode(ref, data)
    ours = ours_cls.decode(data)
    for name in FIELDS:
        assert _same(getattr(ours, name), getattr(ref_obj, name)), (name, data.hex())
    again = ours.encode()
    expected = bytes(transport.bytes_from_bits(ref_obj._pack(True)))
    for name in FIELDS:
        if is_nan_field(data, name):
            assert is_nan_field(again, name), (name, data.hex())
        else:
            assert field_bytes(again, name) == field_bytes(expected, name), (name, data.hex())
    assert ours_cls.decode(again) == ours  # decode . encode . decode == decode (the fuzz target's promise)


def _halves() -> list[int]:
    """Every float16 pattern whose exponent is at an edge (zero and subnormal, smallest normal, largest
    finite, infinity and NaN), both signs, and every 7th of the others."""
    return [b for b in range(0x10000) if (b >> 10) & 0x1F in (0, 1, 2, 29, 30, 31) or b % 7 == 0]


def test_halves_decode_and_re_encode_as_pydronecan(types: tuple[Any, Any]) -> None:
    """Float16 patterns in both float16 fields (the second one's sign flipped), through both byte paths."""
    ours_cls, ref = types
    for bits in _halves():
        _check_bytes(ours_cls, ref, struct.pack("<HH", bits, bits ^ 0x8000) + ZERO[4:])


def _specials() -> st.SearchStrategy[bytes]:
    """Infinities, NaNs with payloads and both signs, extremes and subnormals of each width."""
    f32 = st.sampled_from([0x7F800000, 0xFF800000, 0x7FC00001, 0xFF800001, 0x7F7FFFFF, 0x00000001, 0x80000000])
    f64 = st.sampled_from(
        [0x7FF0000000000000, 0xFFF0000000000000, 0x7FF8000000000001, 0x7FEFFFFFFFFFFFFF, 0x0000000000000001]
    )
    return st.tuples(
        st.integers(0, 0xFFFF),
        st.integers(0, 0xFFFF),
        st.one_of(f32, st.integers(0, 0xFFFFFFFF)),
        st.one_of(f32, st.integers(0, 0xFFFFFFFF)),
        st.one_of(f64, st.integers(0, (1 << 64) - 1)),
        st.one_of(f64, st.integers(0, (1 << 64) - 1)),
    ).map(lambda t: struct.pack("<HHIIQQ", *t))


@settings(max_examples=300, deadline=None, derandomize=True)
@given(data=_specials())
def test_payloads_decode_and_re_encode_as_pydronecan(types: tuple[Any, Any], data: bytes) -> None:
    _check_bytes(*types, data)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(value=st.one_of(st.floats(width=32), st.floats(), st.floats(-70000.0, 70000.0), st.floats(-1e-4, 1e-4)))
def test_random_values_encode_as_pydronecan_sets_them(types: tuple[Any, Any], value: float) -> None:
    """float32 values round to halves as pydronecan's libuavcan-derived converter rounds them."""
    ours_cls, ref = types
    for name in FIELDS:
        if math.isinf(value) and name.startswith("s"):
            continue  # the divergence pinned above
        ours = ours_cls(**{name: value}).encode()
        assert field_bytes(ours, name) == field_bytes(ref_encode(ref, {name: value}), name), (name, value)
