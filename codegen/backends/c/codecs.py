"""The byte codecs of a message as C statements: MAVLink's payload in wire order (the order the IR
gives, extensions last) and uORB's C struct at the offsets PX4's layout gives. Both little-endian,
written byte by byte through ``battgen_wire.h``, so no host's endianness or alignment shows."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, StringType
from .types import ident


@dataclass(frozen=True)
class ByteCodec:
    size: int  # bytes of the whole payload / struct
    packed: int  # uORB: the struct without its trailing padding (as ULog records hold it); else size
    encode: list[str]  # statements writing `m` into `p` (size bytes, zeroed before)
    decode: list[str]  # statements reading `p` (size bytes) into `m`


def _element(f: Field) -> tuple[PrimitiveType, int | None] | None:
    """(element type, count) of a primitive field or fixed array of primitives; None otherwise."""
    t = f.type
    if isinstance(t, StringType):
        return PrimitiveType(PrimitiveKind.CHAR, 8), t.capacity or 1
    if isinstance(t, ArrayType):
        if isinstance(t.element, PrimitiveType) and not t.dynamic:
            return t.element, t.capacity or 1
        return None
    if isinstance(t, PrimitiveType) and t.kind is not PrimitiveKind.VOID:
        return t, None
    return None


def width(t: PrimitiveType) -> int:
    return 1 if t.kind in (PrimitiveKind.BOOL, PrimitiveKind.CHAR) else t.bits // 8


def put(t: PrimitiveType, at: str, v: str) -> str:
    """The statement writing value ``v`` of type ``t`` at byte pointer ``at``."""
    bits = width(t) * 8
    if t.kind is PrimitiveKind.BOOL:
        return f"battgen_put_u8({at}, (uint8_t)({v} ? 1u : 0u));"
    if t.kind is PrimitiveKind.CHAR:
        return f"battgen_put_u8({at}, (uint8_t){v});"
    if t.kind is PrimitiveKind.FLOAT:
        return f"battgen_put_u{bits}({at}, battgen_f{bits}_bits({v}));"
    if t.kind is PrimitiveKind.INT:
        return f"battgen_put_u{bits}({at}, (uint{bits}_t){v});"
    return f"battgen_put_u{bits}({at}, {v});"


def get(t: PrimitiveType, at: str) -> str:
    """The expression reading a value of type ``t`` at byte pointer ``at``."""
    bits = width(t) * 8
    raw = f"battgen_get_u{bits}({at})"
    if t.kind is PrimitiveKind.BOOL:
        return f"{raw} != 0u"
    if t.kind is PrimitiveKind.CHAR:
        return f"(char){raw}"
    if t.kind is PrimitiveKind.FLOAT:
        return f"battgen_f{bits}_from({raw})"
    if t.kind is PrimitiveKind.INT:
        return f"battgen_i{bits}({raw})"
    return raw


def _codec(fields: list[tuple[Field, int]], size: int, packed: int) -> ByteCodec | None:
    encode: list[str] = []
    decode: list[str] = []
    for f, offset in fields:
        shape = _element(f)
        if shape is None:
            return None
        t, count = shape
        name = f"m->{ident(f.name)}"
        if count is None:
            encode.append(put(t, f"p + {offset}", name))
            decode.append(f"{name} = {get(t, f'p + {offset}')};")
            continue
        step = f"{width(t)}u * i"
        encode += [f"for (i = 0; i < {count}u; i++) {{", put(t, f"p + {offset}u + {step}", f"{name}[i]"), "}"]
        decode += [f"for (i = 0; i < {count}u; i++) {{", f"{name}[i] = {get(t, f'p + {offset}u + {step}')};", "}"]
        if isinstance(f.type, StringType):
            decode.append(f"{name}[{count}] = '\\0';")  # the C string's terminator, one past the wire bytes
    return ByteCodec(size, packed, encode, decode)


def mavlink_codec(msg: Message) -> ByteCodec | None:
    """The MAVLink 2 payload of ``msg`` (None if it is not a MAVLink message)."""
    info = msg.mavlink
    if info is None:
        return None
    offset = 0
    placed: list[tuple[Field, int]] = []
    for name in info.wire_order:
        f = msg.field(name)
        shape = _element(f)
        if shape is None:
            return None
        placed.append((f, offset))
        offset += width(shape[0]) * (shape[1] or 1)
    assert offset == info.max_length, f"{msg.qualified_name}: wire order gives {offset} bytes"
    return _codec(placed, info.max_length, info.max_length)


def uorb_codec(msg: Message) -> ByteCodec | None:
    """PX4's C struct of ``msg`` (None if it is not a uORB message or nests another one)."""
    info = msg.uorb
    if info is None:
        return None
    slots = [slot for slot in info.layout if slot.field is not None]
    packed = max((slot.offset + slot.size for slot in slots), default=0)
    return _codec([(msg.field(slot.field), slot.offset) for slot in slots if slot.field], info.struct_size, packed)
