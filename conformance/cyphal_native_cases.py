"""The cases the C library's and the Rust crate's Cyphal codecs replay (conformance/test_cyphal_c.py and
test_cyphal_rust.py): for every bundled Cyphal type, hypothesis-drawn values in pydsdl's form (derandomized,
bounded; the strategy of test_cyphal_codec, which follows pydsdl's reading of each type) plus values beyond
each cast's range, each with what pydsdl, pycyphal and the generated Python class write for it; and byte
strings to read (each value's bytes, truncated, extended with a newer version's trailing bytes, behind a
delimiter header that is right, too long for the data or extended; drawn random bytes) with what pydsdl
reads from them. Nothing here is committed to the generated code."""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import Any

import pydsdl
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_cyphal_codec import BUNDLED, _bundled, plain, values

from codegen.ir import Message

VALUES = 30  # drawn per type
RANDOM_BYTES = 12  # random byte strings read per type


@dataclass
class Value:
    given: dict[str, Any]  # plain data (our field names), what the native struct is built from
    wire: bytes  # pydsdl's serialization
    headed: bytes | None  # with the delimiter header (a delimited type)


@dataclass
class Read:
    data: bytes
    header: bool  # read with a delimiter header
    decoded: dict[str, Any] | None  # what pydsdl reads (plain), None: pydsdl refuses the bytes
    again: bytes | None  # pydsdl's serialization of what it read (None: not compared, NaN held)


@dataclass
class TypeCases:
    name: str
    msg: Message
    sealed: bool
    values: list[Value] = field(default_factory=list)
    reads: list[Read] = field(default_factory=list)


def drawn(strategy: st.SearchStrategy[Any], n: int) -> list[Any]:
    """``n`` examples of a strategy, derandomized (the same on every run) and without a database."""
    out: list[Any] = []

    @settings(max_examples=n, derandomize=True, database=None, deadline=None, suppress_health_check=list(HealthCheck))
    @given(strategy)
    def collect(v: Any) -> None:
        out.append(v)

    collect()
    return out[:n]


def has_nan(v: Any) -> bool:
    if isinstance(v, float):
        return math.isnan(v)
    if isinstance(v, dict):
        return any(has_nan(x) for x in v.values())
    if isinstance(v, list | tuple):
        return any(has_nan(x) for x in v)
    return False


def _f32(*xs: float) -> list[float]:
    """Values as an f32 holds them (the native structs hold a float16 in a float32)."""
    return [struct.unpack("<f", struct.pack("<f", x))[0] for x in xs]


# values beyond a cast's range, set on a drawn value: (type, field, value); float16 values that round
CASTS: dict[str, list[tuple[str, Any]]] = {
    "cyphal.reg.udral.service.battery.Parameters_0_3": [("state_of_health_pct", 200), ("state_of_health_pct", 128)],
    "cyphal.reg.udral.service.common.Readiness_0_1": [("value", 7), ("value", 6)],
    "cyphal.uavcan.node.Health_1_0": [("value", 9), ("value", 255)],
    "cyphal.reg.udral.service.battery.Status_0_2": [
        ("cell_voltages", _f32(70000.0, -70000.0, 65519.0, 65520.0, 1e-8, 2.9802322387695312e-08)),
        ("cell_voltages", _f32(3.1415927410125732, 4.2, 5.960464477539063e-08, -0.0, 0.0001, 4.4e-08)),
        ("cell_voltages", [float("inf"), float("-inf"), 65504.0, 1.0009765625, 1.00048828125, 1.00146484375]),
    ],
}


def _read(t: pydsdl.CompositeType, data: bytes, header: bool) -> Read:
    try:
        got = pydsdl.deserialize(t, data, with_delimiter_header=header)
    except pydsdl.SerDesError:
        return Read(data, header, None, None)
    again = None if has_nan(got) else pydsdl.serialize(t, got)
    return Read(data, header, plain(got), again)


def type_cases(name: str) -> TypeCases:
    """Every value and read of one bundled type (pydsdl's bytes, the Python class checked against them)."""
    from codegen.apps.package import bundled_schemas
    from codegen.frontends.loader import load

    cls, t = _bundled()[name]
    msg = load([bundled_schemas()]).message(name)
    sealed = not isinstance(t, pydsdl.DelimitedType)
    out = TypeCases(name, msg, sealed)
    drawn_values = [plain(v) for v in drawn(values(t), VALUES)]
    for attr, value in CASTS.get(name, []):
        drawn_values.append({**drawn_values[len(out.values) % len(drawn_values)], attr: value})
    for value in drawn_values:
        wire = pydsdl.serialize(t, value)
        assert cls.from_dict(value).encode() == wire, (name, value)  # the Python package writes the same
        headed = None if sealed else pydsdl.serialize(t, value, with_delimiter_header=True)
        out.values.append(Value(value, wire, headed))
    for v in out.values[:VALUES]:
        out.reads.append(_read(t, v.wire, False))
        out.reads.append(_read(t, v.wire[: len(v.wire) // 2], False))  # truncated: zero extension
        out.reads.append(_read(t, v.wire + b"\xa5\x5a\x01", False))  # a newer version's trailing bytes
        if v.headed is not None:
            out.reads.append(_read(t, v.headed, True))
            size = len(v.wire) + 3  # the header counts a newer version's bytes, which are skipped
            out.reads.append(_read(t, size.to_bytes(4, "little") + v.wire + b"\x01\x02\x03\x77", True))
            out.reads.append(_read(t, (size + 2).to_bytes(4, "little") + v.wire + b"\x01", True))  # too long
    for raw in drawn(st.binary(max_size=80), RANDOM_BYTES):
        out.reads.append(_read(t, raw, False))
    return out


def all_cases() -> list[TypeCases]:
    return [type_cases(name) for name in BUNDLED]
