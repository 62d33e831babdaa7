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
from pathlib import Path
from typing import Any

import pydsdl
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_cyphal_codec import _bundled, plain, values

from codegen.apps.schemas.package import bundled_schemas
from codegen.frontends import cyphal
from codegen.frontends.cyphal.build import type_name
from codegen.frontends.loader import load
from codegen.ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema

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


def type_cases(msg: Message, t: pydsdl.CompositeType, cls: Any = None) -> TypeCases:
    """Every value and read of one type: pydsdl's bytes (and, for a bundled type, the Python class checked
    against them)."""
    name = msg.qualified_name
    sealed = not isinstance(t, pydsdl.DelimitedType)
    out = TypeCases(name, msg, sealed)
    # the values a test type exists for come first (the draws differ with the checkout's path, so what they hold
    # is not promised), then the draws
    drawn_values = [*EXPLICIT.get(name, []), *(plain(v) for v in drawn(values(t), VALUES))]
    for attr, value in CASTS.get(name, []):
        drawn_values.append({**drawn_values[len(out.values) % len(drawn_values)], attr: value})
    for value in drawn_values:
        wire = pydsdl.serialize(t, value)
        if cls is not None:
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


def all_cases() -> tuple[Schema, list[TypeCases]]:
    """The bundled types' cases."""
    schema = load([bundled_schemas()])
    return schema, [type_cases(schema.message(name), t, cls) for name, (cls, t) in sorted(_bundled().items())]


# a union (of a number, a nested delimited type and a fixed array), a delimited type nested in a
# structure, alone and in a variable-length array, a signed odd width: what the bundled types lack
DEFINITIONS = {
    "Inner.1.0.dsdl": "uint8 a\nfloat16[<=3] b\n@extent 128\n",
    "Pick.1.0.dsdl": "@union\nuint8 small\nint16 number\nInner.1.0 inner\nfloat32[2] pair\n@sealed\n",
    "Outer.1.0.dsdl": "Inner.1.0 first\nPick.1.0 pick\nInner.1.0[<=2] many\nbool flag\nint5 five\n@extent 1024\n",
}


# per test type, values the native codecs must meet whatever the draws hold: the union holding the delimited type
# with a non-empty array, and a delimited type in the variable-length array
EXPLICIT: dict[str, list[dict[str, Any]]] = {
    "cyphal.test.Pick_1_0": [{"inner": {"a": 7, "b": [1.0, -2.0]}}],
    "cyphal.test.Outer_1_0": [
        {
            "first": {"a": 1, "b": [0.5]},
            "pick": {"inner": {"a": 7, "b": [1.0, -2.0, 65504.0]}},
            "many": [{"a": 2, "b": [0.25]}, {"a": 3, "b": []}],
            "flag": True,
            "five": -9,
        }
    ],
}


def definition_cases(root: Path) -> tuple[Schema, list[TypeCases]]:
    """:data:`DEFINITIONS` written under ``root`` (namespace ``test``) and their cases."""
    folder = root / "test"
    folder.mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (folder / name).write_text(text, encoding="utf-8")
    schema = cyphal.parse_dir(root)
    types = pydsdl.read_namespace(folder, [])
    return schema, [type_cases(schema.message(type_name(t)), t) for t in sorted(types, key=lambda t: t.full_name)]


# ---- what the native programs print of a value -----------------------------------------------------------


def dump(schema: Schema, msg: Message, value: dict[str, Any]) -> str:
    """A read value as the native programs print it: each field ``name=value;`` (a union: ``tag=k;`` and its
    held field), floats by their bits (NaN as ``nan``), composites in braces, arrays in brackets."""
    fields = [f for f in msg.fields if not f.is_padding]
    if msg.is_union:
        k, f = next((k, f) for k, f in enumerate(fields) if f.name in value)
        return f"tag={k};{f.name}={_dump_value(schema, f.type, value[f.name])};"
    return "".join(f"{f.name}={_dump_value(schema, f.type, value[f.name])};" for f in fields)


def _dump_value(schema: Schema, t: FieldType, v: Any) -> str:
    if isinstance(t, CompositeType):
        return "{" + dump(schema, schema.message(t.name), v) + "}"
    if isinstance(t, ArrayType):
        return "[" + ",".join(_dump_value(schema, t.element, e) for e in v) + "]"
    assert isinstance(t, PrimitiveType), t
    if t.kind is PrimitiveKind.FLOAT:
        if math.isnan(v):
            return "nan"
        if t.bits > 32:
            return f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"
        return f"{struct.unpack('<I', struct.pack('<f', v))[0]:08x}"
    if t.kind is PrimitiveKind.BOOL:
        return "1" if v else "0"
    return str(int(v))
