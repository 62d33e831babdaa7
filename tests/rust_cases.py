"""The Rust crate's replay data, written by the Python side at test time: every record of the
conformance vectors (``battgen vectors``, inputs and outputs, of every converter between the message
sides) with what the generated Python package makes of it -- the MAVLink 2 payload and frame, the
uORB struct, the decoded values and the validator's problems -- as Rust test cases. The crate's
tests (``rust_replay.rs`` beside the test) must give identical bytes, values and problems.

Nothing here is committed to the crate: the cases are rendered into a temporary copy of it.
"""

from __future__ import annotations

import importlib
import math
import random
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import generated.convert as converters
from codegen.apps.conversion.vectors import SIDES, VectorWriter
from codegen.backends.rust.model import type_path
from codegen.backends.rust.naming import field_ident, snake
from codegen.backends.rust.types import scalar
from codegen.ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema, StringType
from codegen.ir.numbers import from_json_number

# the validator rules of one value (the Rust replay compares every problem, cross-field rules too)
FIELD_RULES = frozenset({"nan", "type-bounds", "range", "enum", "bitmask", "length"})
TARGETS = (
    "uorb",
    "uorb_v0",
    "uorb_info",
    "mavlink",
    "mavlink_info",
    "mavlink_v2",
    "dronecan",
    "ardupilot_battery",
    "cbat",
)
HARNESS = Path(__file__).parent / "backends" / "rust_replay.rs"


def vector_pairs() -> list[tuple[str, str, str]]:
    """(source, target, policy) of every converter between message sides, strict and px4."""
    pairs = sorted(k for k in converters.CONVERTERS if k[0] in SIDES and k[1] in TARGETS)
    return [(s, t, p) for s, t in pairs for p in converters.POLICIES.get((s, t), ("strict",))]


def _from_json(value: object) -> object:
    """JSON data back to values: the spellings of NaN and the infinities as floats."""
    if isinstance(value, str):
        number = from_json_number(value)
        return value if number is None else number
    if isinstance(value, list):
        return [_from_json(v) for v in value]
    if isinstance(value, dict):
        return {k: _from_json(v) for k, v in value.items()}
    return value


def _parts(data: object, items: tuple[tuple[str, Any], ...]) -> Iterator[tuple[Any, dict[str, Any]]]:
    """The messages of one side's record: a bare object for a one-message side, else by alias."""
    if not isinstance(data, dict):
        return
    if len(items) == 1:
        yield items[0][1], data
        return
    for alias, cls in items:
        part = data.get(alias)
        if isinstance(part, dict):
            yield cls, part


def vector_records() -> Iterator[tuple[str, Any, dict[str, Any]]]:
    """(vector id, generated class, plain record) of every input and output of every vector."""
    for source, target, policy in vector_pairs():
        writer = VectorWriter(source, target, policy)
        doc = writer.document()
        sides = ((writer.conversion.source.items, "input"), (writer.conversion.target.items, "output"))
        for vector in doc["vectors"]:  # type: ignore[attr-defined]
            for items, key in sides:
                for cls, plain in _parts(_from_json(vector.get(key)), items):
                    yield f"{source}->{target}/{policy}/{vector['id']}/{key}", cls, plain


class Unrepresentable(ValueError):
    """A value the Rust field's type cannot hold (the Python object holds any int or float)."""


def _f32_bits(value: object, exact: bool) -> int:
    """The f32 bits of a value; not ``exact``: rounded to the nearest f32, as the encoders round it."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise Unrepresentable(value)
    try:
        packed = struct.pack("<f", value)
    except OverflowError:
        raise Unrepresentable(value) from None
    back = struct.unpack("<f", packed)[0]
    if exact and not (back == value or (math.isnan(back) and math.isnan(value))):
        raise Unrepresentable(value)  # the Rust f32 would round it
    return int.from_bytes(packed, "little")


def _int(t: PrimitiveType, value: object) -> str:
    rust = scalar(t)
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise Unrepresentable(value)
    bits = int(rust[1:])
    low, high = (0, (1 << bits) - 1) if rust[0] == "u" else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
    if not low <= value <= high:
        raise Unrepresentable(value)
    return str(value)


def _primitive(t: PrimitiveType, value: object, exact: bool) -> str:
    rust = scalar(t)
    if rust == "bool":
        if value not in (True, False, 0, 1):
            raise Unrepresentable(value)
        return "true" if value else "false"
    if t.kind is PrimitiveKind.CHAR:
        raw = value.encode("latin-1") if isinstance(value, str) else bytes([int(value)])  # type: ignore[call-overload]
        return str(raw[0]) if raw else "0"
    if rust == "f32":
        return f"f32::from_bits({_f32_bits(value, exact):#010x})"
    if rust == "f64":
        if not isinstance(value, int | float):
            raise Unrepresentable(value)
        return f"f64::from_bits({struct.unpack('<Q', struct.pack('<d', value))[0]:#018x})"
    return _int(t, value)


def _bytes(value: object, capacity: int) -> list[str]:
    if isinstance(value, str):
        raw = value.encode("utf-8")
    elif isinstance(value, bytes | bytearray | list):
        raw = bytes(value)
    else:
        raise Unrepresentable(value)
    if len(raw) > capacity:
        raise Unrepresentable(value)
    return [str(b) for b in raw] + ["0"] * (capacity - len(raw))


def value_literal(schema: Schema, t: FieldType, value: object, exact: bool = True) -> tuple[str, int | None]:
    """(Rust expression, used length of a dynamic array) of ``value`` in a field of type ``t``; with
    ``exact``, a float the Rust f32 would round is Unrepresentable."""
    if isinstance(t, PrimitiveType):
        return _primitive(t, value, exact), None
    if isinstance(t, StringType):
        return "[" + ", ".join(_bytes(value, t.capacity or 1)) + "]", None
    if isinstance(t, CompositeType):
        if not isinstance(value, dict):
            raise Unrepresentable(value)
        return struct_literal(schema, schema.message(t.name), value, exact), None
    assert isinstance(t, ArrayType)
    cap = t.capacity or 1
    el = t.element
    if isinstance(el, PrimitiveType) and el.kind is PrimitiveKind.CHAR and isinstance(value, str):
        return "[" + ", ".join(_bytes(value, cap)) + "]", None
    if isinstance(value, bytes | bytearray | str):
        value = list(value.encode("utf-8") if isinstance(value, str) else value)
    if not isinstance(value, list) or len(value) > cap or (not t.dynamic and len(value) != cap):
        raise Unrepresentable(value)
    items = [value_literal(schema, el, v, exact)[0] for v in value]
    if len(items) < cap:
        zero = value_literal(schema, el, _zero(el))[0]
        items += [zero] * (cap - len(items))
    return "[" + ", ".join(items) + "]", len(value) if t.dynamic else None


def _zero(t: FieldType) -> object:
    if isinstance(t, PrimitiveType):
        return False if t.kind is PrimitiveKind.BOOL else 0
    if isinstance(t, CompositeType):
        return {}
    return []


def struct_literal(schema: Schema, msg: Message, plain: Mapping[str, object], exact: bool = True) -> str:
    """The message as a Rust struct expression (fields the record leaves out at their zero)."""
    parts = []
    for f in msg.fields:
        if f.is_padding:
            continue
        ident = field_ident(f.name)
        value = plain.get(f.name, _zero(f.type))
        if isinstance(f.type, CompositeType) and isinstance(value, dict):
            inner = schema.message(f.type.name)
            value = {g.name: value.get(g.name, _zero(g.type)) for g in inner.fields if not g.is_padding}
        text, length = value_literal(schema, f.type, value, exact)
        parts.append(f"{ident}: {text}")
        if length is not None:
            parts.append(f"{ident}_len: {length}")
    return type_path(msg.qualified_name).replace("crate::", "battgen::", 1) + " { " + ", ".join(parts) + " }"


def _bytes_literal(data: bytes) -> str:
    return "&[" + ", ".join(str(b) for b in data) + "]"


def _problems(obj: Any) -> str:
    found = [f'"{v.path} {v.rule}"' for v in obj.validate()]
    return "&[" + ", ".join(found) + "]"


@dataclass
class Replay:
    """The cases of one message, as lines of a Rust ``vec![...]``, and the ids already taken."""

    kind: str  # mavlink, uorb, values
    qualified: str
    cases: list[str] = field(default_factory=list)
    seen: set[str] = field(default_factory=set)
    skipped: int = 0


def _value(schema: Schema, msg: Message, obj: Any, decoded: Any) -> tuple[str, bool]:
    """The record as the Rust struct holds it, and whether that is exactly the Python record: its
    floats rounded to f32 (as every encoder rounds them), or, when Rust cannot hold it at all (a
    float beyond f32), the decoded record."""
    plain = obj.to_dict()
    try:
        return struct_literal(schema, msg, plain), True
    except Unrepresentable:
        pass
    try:
        return struct_literal(schema, msg, plain, exact=False), False
    except Unrepresentable:
        return struct_literal(schema, msg, decoded.to_dict()), False


def _case(schema: Schema, msg: Message, replay: Replay, cid: str, obj: Any) -> str | None:
    """One Rust case of ``obj`` (None when the Python side cannot encode it or Rust cannot hold it).

    A case holds the value given, the value decoded from the Python encoding (which the validator
    checks), and the Python encoding."""
    cls = type(obj)
    try:
        if replay.kind == "mavlink":
            payload = obj.encode()
            seq = len(replay.cases) % 256
            frame = obj.encode_frame(seq=seq, sysid=1, compid=1)
            decoded = cls.decode(payload)
            signed = obj.encode_frame(seq=seq, sysid=1, compid=1, signature=bytes(range(13)))
            v1 = "None"
            if cls.MSG_ID < 256:  # MAVLink 1: the base payload, extensions decoded as zero
                frame_v1 = obj.encode_frame(seq=seq, sysid=1, compid=1, mavlink1=True)
                decoded_v1 = struct_literal(schema, msg, cls.decode_frame(frame_v1).to_dict())
                v1 = f"Some(({_bytes_literal(frame_v1)}, {decoded_v1}))"
            wire = f"{_bytes_literal(payload)}, {_bytes_literal(frame)}, {seq}, {v1}, {_bytes_literal(signed)}"
        elif replay.kind == "uorb":
            payload = obj.encode()
            decoded = cls.decode(payload)
            wire = _bytes_literal(payload)
        elif replay.kind == "dronecan":
            payload = obj.encode()
            fd = obj.encode(tao=False)
            decoded = cls.decode(payload)
            wire = f"{_bytes_literal(payload)}, {_bytes_literal(fd)}"
        else:
            value = struct_literal(schema, msg, obj.to_dict())
            body = f"{_rust_str(cid)}, {value}, {_problems(obj)}"
            key = value
        if replay.kind != "values":
            value, same = _value(schema, msg, obj, decoded)
            exact = struct_literal(schema, msg, decoded.to_dict())
            # the value's own problems where Rust holds exactly the Python record
            given = f"Some({_problems(obj)})" if same else "None"
            body = f"({_rust_str(cid)}, {value}, {given}, {exact}), {wire}, {_problems(decoded)}"
            key = value + exact
    except (Unrepresentable, ValueError, TypeError, OverflowError, struct.error):
        replay.skipped += 1
        return None
    if key in replay.seen:
        return None
    replay.seen.add(key)
    return f"({body}),"


def _rust_str(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


RANDOM_RECORDS = 40  # per message with a codec, on top of the vectors


def _f32(x: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


def _random_float(rng: random.Random) -> float:
    """Any f32 (NaN canonical), or a value near float16's edges: its largest, beyond, subnormal;
    always exactly an f32, so Rust holds the record the Python side validates."""
    pick = rng.random()
    if pick < 0.4:
        bits = rng.getrandbits(32)
        if bits & 0x7F800000 == 0x7F800000 and bits & 0x7FFFFF:
            return math.nan
        return float(struct.unpack("<f", struct.pack("<I", bits))[0])
    sign = rng.choice((-1.0, 1.0))
    if pick < 0.6:
        return _f32(sign * rng.uniform(65000.0, 70000.0))
    if pick < 0.8:
        return _f32(sign * rng.uniform(0, 1e-4))
    return _f32(rng.uniform(-100.0, 100.0))


def _random_value(schema: Schema, t: FieldType, rng: random.Random) -> object:
    if isinstance(t, PrimitiveType):
        if t.kind is PrimitiveKind.BOOL:
            return rng.random() < 0.5
        if t.kind is PrimitiveKind.FLOAT:
            return _random_float(rng)
        rust = scalar(t)
        bits = int(rust[1:]) if rng.random() < 0.5 else t.bits  # beyond a DSDL odd width half the time
        if t.kind is PrimitiveKind.UINT:
            return rng.randrange(0, 1 << bits)
        return rng.randrange(-(1 << (bits - 1)), 1 << (bits - 1))
    if isinstance(t, StringType) or (
        isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.element.kind is PrimitiveKind.CHAR
    ):
        cap = t.capacity or 1
        return "".join(rng.choice("abcXYZ019 -") for _ in range(rng.randint(0, cap)))
    if isinstance(t, ArrayType):
        cap = t.capacity or 1
        n = rng.randint(0, cap) if t.dynamic else cap
        return [_random_value(schema, t.element, rng) for _ in range(n)]
    assert isinstance(t, CompositeType)
    return _random_record(schema, schema.message(t.name), rng)


def _random_record(schema: Schema, msg: Message, rng: random.Random) -> dict[str, object]:
    return {f.name: _random_value(schema, f.type, rng) for f in msg.fields if not f.is_padding}


def random_records(schema: Schema, msg: Message) -> Iterator[tuple[str, dict[str, object]]]:
    """Seeded random records of ``msg`` (the same every run): what the vectors do not reach, such
    as float16 rounding and saturation, and the messages no converter reads or writes."""
    rng = random.Random(msg.qualified_name)
    for i in range(RANDOM_RECORDS):
        yield f"random/{i}", _random_record(schema, msg, rng)


def generated_classes(schema: Schema) -> dict[str, Any]:
    """Qualified name -> the generated Python class, of every message the crate has a codec for."""
    out: dict[str, Any] = {}
    for msg in schema.messages:
        if msg.format.value not in ("mavlink", "uorb", "dronecan") or (msg.dronecan is not None and msg.dronecan.union):
            continue
        module = importlib.import_module("generated." + msg.qualified_name.rsplit(".", 1)[0])
        out[msg.qualified_name] = next(
            cls for cls in vars(module).values() if getattr(cls, "QUALIFIED_NAME", None) == msg.qualified_name
        )
    return out


def _records(schema: Schema, classes: Mapping[str, Any]) -> Iterator[tuple[str, Any, dict[str, Any]]]:
    yield from vector_records()
    for qualified, cls in sorted(classes.items()):
        for cid, plain in random_records(schema, schema.message(qualified)):
            yield cid, cls, plain


def collect(schema: Schema, classes: Mapping[str, Any]) -> list[Replay]:
    """The replays of every message the vectors reach and of ``classes`` (qualified name ->
    generated class: random records), in a stable order."""
    replays: dict[str, Replay] = {}
    for cid, cls, plain in _records(schema, classes):
        qualified = getattr(cls, "QUALIFIED_NAME", "")
        try:
            msg = schema.message(qualified)
        except KeyError:
            continue
        kind = "mavlink" if msg.mavlink else "uorb" if msg.uorb else "dronecan" if msg.dronecan else "values"
        replay = replays.setdefault(qualified, Replay(kind, qualified))
        try:
            obj = cls.from_dict(plain)
        except (ValueError, TypeError):
            replay.skipped += 1
            continue
        line = _case(schema, msg, replay, cid, obj)
        if line is not None:
            replay.cases.append(line)
    return [replays[q] for q in sorted(replays)]


def replay_test_name(replay: Replay) -> str:
    return snake(replay.qualified.replace(".", "_"))


def render_replay(schema: Schema, replays: list[Replay]) -> str:
    """The crate's ``tests/replay.rs``: the harness, then one test per message over its cases."""
    out = [HARNESS.read_text(encoding="utf-8")]
    for r in replays:
        rust = type_path(r.qualified).replace("crate::", "battgen::", 1)
        out.append("#[test]")
        out.append(f"fn {replay_test_name(r)}() {{")
        out.append(f"    let cases: Vec<{r.kind.capitalize()}Case<{rust}>> = vec![")
        out += ["        " + c for c in r.cases]
        out.append("    ];")
        out.append(f"    replay_{r.kind}(&cases, {len(r.cases)});")
        out.append("}")
        out.append("")
    return "\n".join(out)
