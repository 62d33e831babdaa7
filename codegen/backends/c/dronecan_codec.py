"""DroneCAN's bit-level codec of a message as C statements over ``battgen_wire.h``'s bit writer and
reader: each field in schema order at its DSDL width (saturated or truncated as its cast mode says,
float16 rounded as the reference), dynamic arrays behind their length, and the last field told of
the tail array optimisation as pydronecan and battgen's Python codec tell it."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, CastMode, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema
from .types import ident, scalar, type_name


@dataclass(frozen=True)
class BitCodec:
    max_bytes: int
    put: list[str]  # statements over `m`, `w` and `tao`, returning a battgen_error on failure
    get: list[str]  # statements over `m`, `r`, `tao` and a scratch `u`
    loops: bool  # whether the statements use `i` (and `k`)


def _min_bits(schema: Schema, t: FieldType) -> int:
    if isinstance(t, PrimitiveType):
        return t.bits
    if isinstance(t, ArrayType):
        return 0 if t.dynamic else (t.capacity or 0) * _min_bits(schema, t.element)
    assert isinstance(t, CompositeType)
    m = schema.message(t.name)
    return m.dronecan.min_bitlen if m.dronecan is not None else 0


def _eligible(schema: Schema, t: FieldType) -> bool:
    """A dynamic array the tail array optimisation may drop the length of."""
    return isinstance(t, ArrayType) and t.dynamic and _min_bits(schema, t.element) >= 8


def _sensitive(schema: Schema, t: FieldType) -> bool:
    """Whether the encoding of ``t`` depends on the tail array flag it is given."""
    if isinstance(t, ArrayType):
        return _eligible(schema, t) or _sensitive(schema, t.element)
    if isinstance(t, CompositeType):
        m = schema.message(t.name)
        if m.dronecan is not None and m.dronecan.union:  # the held field is told the union's flag
            return any(_sensitive(schema, f.type) for f in m.fields)
        return bool(m.fields) and _sensitive(schema, m.fields[-1].type)
    return False


def _put_value(t: PrimitiveType, v: str) -> str:
    """The bits (a uint64_t expression) of value expression ``v`` of type ``t``."""
    c = scalar(t)
    saturated = t.cast is CastMode.SATURATED
    if t.kind is PrimitiveKind.BOOL:
        return f"(uint64_t)({v} ? 1u : 0u)"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return f"(uint64_t)battgen_f16_{'saturated' if saturated else 'truncated'}({v})"
        return f"(uint64_t)battgen_f{t.bits}_bits({v})"
    full = t.bits == int(c.removeprefix("u").removeprefix("int")[:-2])
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


def _read(bits: int) -> str:
    return f"if (!battgen_bits_get(r, {bits}u, &u)) {{ return BATTGEN_ERR_SHORT; }}"


def union_tag_bits(count: int) -> int:
    """pydronecan's tag width: ceil(log2(fields))."""
    return max(count - 1, 0).bit_length()


def dronecan_codec(schema: Schema, msg: Message) -> BitCodec | None:
    """The codec of ``msg`` (None if it is not a DroneCAN message, or holds arrays of composites,
    which DroneCAN v0's battery messages do not). A union writes its tag (``m->union_tag``, in
    ceil(log2(fields)) bits) and then the one field it holds, told the union's own tail array flag."""
    info = msg.dronecan
    if info is None:
        return None
    put: list[str] = []
    get: list[str] = []
    loops = False
    if info.union:
        n = len(msg.fields)
        bits = union_tag_bits(n)
        put += [f"if (m->union_tag >= {n}u) {{ return BATTGEN_ERR_TAG; }}"]
        put += [f"battgen_bits_put(w, (uint64_t)m->union_tag, {bits}u);"] if bits else []
        if bits:
            get += [_read(bits), f"if (u >= {n}u) {{ return BATTGEN_ERR_TAG; }}", "m->union_tag = (uint8_t)u;"]
        else:
            get.append("m->union_tag = 0u;")
        put.append("switch (m->union_tag) {")
        get.append("switch (m->union_tag) {")
        for k, f in enumerate(msg.fields):
            branch_put: list[str] = []
            branch_get: list[str] = []
            tao = "tao" if _sensitive(schema, f.type) else "false"
            if not _field(schema, f, tao, branch_put, branch_get):
                return None
            loops = loops or isinstance(f.type, ArrayType)
            put += [f"case {k}u: {{", *branch_put, "break;", "}"]
            get += [f"case {k}u: {{", *branch_get, "break;", "}"]
        put += ["default:", "break;", "}"]
        get += ["default:", "break;", "}"]
        return BitCodec(max(1, (info.max_bitlen + 7) // 8), put, get, loops)  # C has no empty array
    for n, f in enumerate(msg.fields):
        last = n == len(msg.fields) - 1
        tao = "tao" if last and _sensitive(schema, f.type) else "false"
        if not _field(schema, f, tao, put, get):
            return None
        loops = loops or isinstance(f.type, ArrayType)
    return BitCodec(max(1, (info.max_bitlen + 7) // 8), put, get, loops)  # C has no empty array


def _field(schema: Schema, f: Field, tao: str, put: list[str], get: list[str]) -> bool:
    """The statements of one field (False: a type the C codec does not write)."""
    t = f.type
    if f.is_padding:
        assert isinstance(t, PrimitiveType)
        put.append(f"battgen_bits_put(w, 0u, {t.bits}u);")
        get.append(_read(t.bits))
        return True
    name = f"m->{ident(f.name)}"
    if isinstance(t, PrimitiveType):
        put.append(f"battgen_bits_put(w, {_put_value(t, name)}, {t.bits}u);")
        get.extend([_read(t.bits), f"{name} = {_get_value(t)};"])
    elif isinstance(t, CompositeType):
        inner = type_name(t.name)
        put.extend([f"e = {inner}_put(&{name}, w, {tao});", "if (e != BATTGEN_OK) { return e; }"])
        get.extend([f"e = {inner}_get(&{name}, r, {tao});", "if (e != BATTGEN_OK) { return e; }"])
    elif isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType):
        _array(schema, f, t, t.element, name, tao, put, get)
    else:
        return False
    return True


def _array(
    schema: Schema, f: Field, t: ArrayType, el: PrimitiveType, name: str, tao: str, put: list[str], get: list[str]
) -> None:
    cap = t.capacity or 0
    put_el = f"battgen_bits_put(w, {_put_value(el, f'{name}[i]')}, {el.bits}u);"
    get_el = [_read(el.bits), f"{name}[i] = {_get_value(el)};"]
    if not t.dynamic:
        put += [f"for (i = 0; i < {cap}u; i++) {{", put_el, "}"]
        get += [f"for (i = 0; i < {cap}u; i++) {{", *get_el, "}"]
        return
    bits = cap.bit_length()
    length = f"{name}_len"
    put += [f"if ({length} > {cap}u) {{ return BATTGEN_ERR_LENGTH; }}"]
    count = f"battgen_bits_put(w, (uint64_t){length}, {bits}u);"
    tail = _eligible(schema, t) and tao == "tao"
    put += ["if (!tao) {", count, "}"] if tail else [count]
    put += [f"for (i = 0; i < {length}; i++) {{", put_el, "}"]
    if tail:
        get += [
            "if (tao) {",
            f"k = battgen_bits_remaining(r) / {el.bits}u;",
            f"if (battgen_bits_remaining(r) - k * {el.bits}u >= 8u) {{ return BATTGEN_ERR_PARTIAL_ELEMENT; }}",
            "} else {",
            _read(bits),
            "k = (size_t)u;",
            "}",
        ]
    else:
        get += [_read(bits), "k = (size_t)u;"]
    get += [
        f"if (k > {cap}u) {{ return BATTGEN_ERR_LENGTH; }}",
        f"{length} = (uint16_t)k;",
        "for (i = 0; i < k; i++) {",
        *get_el,
        "}",
    ]
