"""Cyphal's (UAVCAN v1) bit-level codec of a message as C statements over ``battgen_cyphal.h``'s
writer and reader, the rules of the Python runtime ``_cyphal.py`` (pydsdl's ``serialize``) spelled
out per type: bits least significant first, a composite (and an array of composites) at a byte
boundary, no tail array optimisation, a variable-length array behind its length prefix (8, 16, 32 or
64 bits), a union behind its tag, a delimited type nested in another behind its uint32 length in bytes,
float16 rounded to nearest even, saturated and truncated casts as the field's cast mode says."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, CastMode, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema
from .types import ident, scalar, type_name

DELIMITER_BYTES = 4  # the uint32 delimiter header


@dataclass(frozen=True)
class CyphalCodec:
    max_bytes: int  # the longest serialization, without a delimiter header
    extent_bytes: int
    sealed: bool
    fixed_port_id: int | None
    put: list[str]  # statements over `m` and `w` (and `e`, `i`, `h`), returning a battgen_error on failure
    get: list[str]  # statements over `m` and `r` (and `e`, `i`, `u`, `sub`)

    @property
    def buffer_bytes(self) -> int:
        """What `_encode` writes at most: a delimited type's header included (C has no empty array)."""
        return max(1, self.max_bytes + (0 if self.sealed else DELIMITER_BYTES))


def length_bits(capacity: int) -> int:
    """The width of a variable-length array's length prefix (pydsdl's ``length_field_type``)."""
    return next(bits for bits in (8, 16, 32, 64) if capacity.bit_length() <= bits)


def _aligned(t: FieldType) -> bool:
    """A composite, and an array of them, starts at a byte (any other value at any bit)."""
    if isinstance(t, ArrayType):
        return _aligned(t.element)
    return isinstance(t, CompositeType)


def _put_value(t: PrimitiveType, v: str) -> str:
    """The bits (a uint64_t expression) of value expression ``v`` of type ``t``. A float32 or float64
    held in its own C type is within its range, so only float16 has a cast to apply."""
    saturated = t.cast is CastMode.SATURATED
    if t.kind is PrimitiveKind.BOOL:
        return f"(uint64_t)({v} ? 1u : 0u)"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return f"(uint64_t)battgen_cyphal_f16({v}, {'true' if saturated else 'false'})"
        return f"(uint64_t)battgen_f{t.bits}_bits({v})"
    full = t.bits == int(scalar(t).removeprefix("u").removeprefix("int")[:-2])
    if t.kind is PrimitiveKind.UINT:
        return f"(uint64_t){v}" if full or not saturated else f"battgen_saturate_u((uint64_t){v}, {t.bits}u)"
    return f"(uint64_t)(int64_t){v}" if full or not saturated else f"battgen_saturate_i((int64_t){v}, {t.bits}u)"


def _get_value(t: PrimitiveType) -> str:
    """The value of type ``t`` from the raw bits in ``u``."""
    c = scalar(t)
    if t.kind is PrimitiveKind.BOOL:
        return "u != 0u"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return "battgen_f16_value((uint16_t)u)"
        return f"battgen_f{t.bits}_from((uint{t.bits}_t)u)"
    if t.kind is PrimitiveKind.UINT:
        return f"({c})u"
    return f"({c})battgen_sign_extend(u, {t.bits}u)"


class _Writer:
    def __init__(self, schema: Schema) -> None:
        self.schema = schema
        self.put: list[str] = []
        self.get: list[str] = []

    def field(self, f: Field) -> None:
        t = f.type
        if f.is_padding:
            assert isinstance(t, PrimitiveType)
            self.put.append(f"w->bit += {t.bits}u;")  # the buffer is zeroed: padding is written by skipping it
            self.get.append(f"r->bit += {t.bits}u;")
            return
        name = f"m->{ident(f.name)}"
        if _aligned(t):
            self.put.append("w->bit = battgen_cyphal_aligned(w->bit);")
            self.get.append("r->bit = battgen_cyphal_aligned(r->bit);")
        if isinstance(t, ArrayType):
            self.array(t, name)
        else:
            self.value(t, name)

    def value(self, t: FieldType, name: str) -> None:
        if isinstance(t, PrimitiveType):
            self.put.append(f"battgen_cyphal_put(w, {_put_value(t, name)}, {t.bits}u);")
            self.get += [f"u = battgen_cyphal_get(r, {t.bits}u);", f"{name} = {_get_value(t)};"]
            return
        assert isinstance(t, CompositeType), t
        inner = type_name(t.name)
        info = self.schema.message(t.name).cyphal
        assert info is not None, t.name
        fail = "if (e != BATTGEN_OK) { return e; }"
        if info.sealed:
            self.put += [f"e = {inner}_put(&{name}, w);", fail]
            self.get += [f"e = {inner}_get(&{name}, r);", fail]
            return
        # a delimited type: its length in bytes first, written once its own bytes are
        self.put += [
            "h = w->bit / 8u;",
            f"w->bit += {8 * DELIMITER_BYTES}u;",
            f"e = {inner}_put(&{name}, w);",
            fail,
            "battgen_put_u32(w->buf + h, (uint32_t)(w->bit / 8u - h - 4u));",
        ]
        self.get += ["e = battgen_cyphal_delimited(r, &sub);", fail, f"e = {inner}_get(&{name}, &sub);", fail]

    def array(self, t: ArrayType, name: str) -> None:
        cap = t.capacity or 0
        element = f"{name}[i]"
        el_put, el_get = self.put, self.get
        self.put, self.get = [], []
        if _aligned(t.element):
            self.put.append("w->bit = battgen_cyphal_aligned(w->bit);")
            self.get.append("r->bit = battgen_cyphal_aligned(r->bit);")
        self.value(t.element, element)
        body_put, body_get = self.put, self.get
        self.put, self.get = el_put, el_get
        if not t.dynamic:
            self.put += [f"for (i = 0; i < {cap}u; i++) {{", *body_put, "}"]
            self.get += [f"for (i = 0; i < {cap}u; i++) {{", *body_get, "}"]
            return
        bits = length_bits(cap)
        length = f"{name}_len"
        self.put += [
            f"if ({length} > {cap}u) {{ return BATTGEN_ERR_LENGTH; }}",
            f"battgen_cyphal_put(w, (uint64_t){length}, {bits}u);",
            f"for (i = 0; i < {length}; i++) {{",
            *body_put,
            "}",
        ]
        self.get += [
            f"u = battgen_cyphal_get(r, {bits}u);",
            f"if (u > {cap}u) {{ return BATTGEN_ERR_LENGTH; }}",
            f"{length} = (uint16_t)u;",
            f"for (i = 0; i < {length}; i++) {{",
            *body_get,
            "}",
        ]


def cyphal_codec(schema: Schema, msg: Message) -> CyphalCodec | None:
    """The codec of ``msg`` (None if it is not a Cyphal type). A union writes its tag (``m->union_tag``,
    in the tag width pydsdl gives) and then the one field it holds; a tag naming no field is an error
    both ways."""
    info = msg.cyphal
    if info is None:
        return None
    out = _Writer(schema)
    if info.union:
        n = len(msg.fields)
        bits = info.union_tag_bits
        out.put += [
            f"if (m->union_tag >= {n}u) {{ return BATTGEN_ERR_TAG; }}",
            f"battgen_cyphal_put(w, (uint64_t)m->union_tag, {bits}u);",
            "switch (m->union_tag) {",
        ]
        out.get += [
            f"u = battgen_cyphal_get(r, {bits}u);",
            f"if (u >= {n}u) {{ return BATTGEN_ERR_TAG; }}",
            "m->union_tag = (uint8_t)u;",
            "switch (m->union_tag) {",
        ]
        for k, f in enumerate(msg.fields):
            out.put.append(f"case {k}u: {{")
            out.get.append(f"case {k}u: {{")
            out.field(f)
            out.put += ["break;", "}"]
            out.get += ["break;", "}"]
        out.put += ["default:", "break;", "}"]
        out.get += ["default:", "break;", "}"]
    else:
        for f in msg.fields:
            out.field(f)
    out.put.append("w->bit = battgen_cyphal_aligned(w->bit);")
    out.get.append("r->bit = battgen_cyphal_aligned(r->bit);")
    return CyphalCodec((info.max_bitlen + 7) // 8, info.extent // 8, info.sealed, info.fixed_port_id, out.put, out.get)
