"""The byte codecs of a message as Rust statements: MAVLink's payload in wire order (the order the
IR gives, extensions last) and uORB's C struct at the offsets the IR's layout gives. Both are
little-endian; a field is written element by element with ``to_le_bytes``."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, StringType
from .types import scalar


@dataclass(frozen=True)
class Codec:
    size: int  # bytes of the whole payload / struct
    encode: list[str]  # statements writing into `out` (a `&mut [u8]` of `size` bytes)
    decode: list[str]  # `ident: expression,` lines of a struct expression over `b` (a `&[u8; size]`)


def _element(f: Field) -> tuple[PrimitiveType, int | None] | None:
    """(element type, count) of a primitive field or array of primitives; None for anything else."""
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


def _width(t: PrimitiveType) -> int:
    return 1 if t.kind in (PrimitiveKind.BOOL, PrimitiveKind.CHAR) else t.bits // 8


def _encode(ident: str, t: PrimitiveType, count: int | None, offset: int) -> list[str]:
    rust = scalar(t)
    if count is None:
        value = f"u8::from(self.{ident})" if rust == "bool" else f"self.{ident}"
        return [f"wire::put(out, {offset}, &{value}.to_le_bytes());"]
    if rust == "u8":
        return [f"wire::put(out, {offset}, &self.{ident});"]
    value = "u8::from(*v)" if rust == "bool" else "v"
    return [
        f"for (i, v) in self.{ident}.iter().enumerate() {{",
        f"wire::put(out, {_at(offset, _width(t))}, &{value}.to_le_bytes());",
        "}",
    ]


def _at(offset: int, width: int) -> str:
    """The offset of element ``i`` (clippy refuses ``0 + ...`` and ``1 * i``)."""
    step = "i" if width == 1 else f"{width} * i"
    return step if offset == 0 else f"{offset} + {step}"


def _decode(ident: str, t: PrimitiveType, count: int | None, offset: int) -> str:
    rust = scalar(t)
    w = _width(t)
    if count is None:
        if rust == "bool":
            return f"{ident}: b[{offset}] != 0,"
        if rust == "u8":
            return f"{ident}: b[{offset}],"
        return f"{ident}: {rust}::from_le_bytes(wire::take(b, {offset})),"
    if rust == "u8":
        return f"{ident}: wire::take(b, {offset}),"
    if rust == "bool":
        return f"{ident}: core::array::from_fn(|i| b[{_at(offset, 1)}] != 0),"
    return f"{ident}: core::array::from_fn(|i| {rust}::from_le_bytes(wire::take(b, {_at(offset, w)}))),"


def _codec(fields: list[tuple[Field, int]], idents: dict[str, str], size: int) -> Codec | None:
    encode: list[str] = []
    decode: list[str] = []
    for f, offset in fields:
        shape = _element(f)
        if shape is None:
            return None
        t, count = shape
        encode += _encode(idents[f.name], t, count, offset)
        decode.append(_decode(idents[f.name], t, count, offset))
    return Codec(size, encode, decode)


def mavlink_codec(msg: Message, idents: dict[str, str]) -> Codec | None:
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
        offset += _width(shape[0]) * (shape[1] or 1)
    assert offset == info.max_length, f"{msg.qualified_name}: wire order gives {offset} bytes"
    return _codec(placed, idents, info.max_length)


def uorb_codec(msg: Message, idents: dict[str, str]) -> Codec | None:
    """PX4's C struct of ``msg`` (None if it is not a uORB message or nests another one)."""
    info = msg.uorb
    if info is None:
        return None
    placed = [(msg.field(slot.field), slot.offset) for slot in info.layout if slot.field is not None]
    return _codec(placed, idents, info.struct_size)
