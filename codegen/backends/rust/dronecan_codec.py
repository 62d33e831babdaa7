"""DroneCAN's bit-level codec of a message as Rust statements over ``dronecan_wire``'s bit writer
and reader: each field in schema order at its DSDL width (saturated or truncated as its cast mode
says, float16 rounded as the reference), dynamic arrays behind their length, the last field told
of the tail array optimisation as pydronecan and battgen's Python codec tell it."""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import ArrayType, CastMode, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema
from .types import scalar

WIRE = "dronecan_wire"


@dataclass(frozen=True)
class DronecanCodec:
    max_bytes: int
    put: list[str]  # statements over `self`, `w` and `tao`
    get: list[str]  # statements binding `f_<ident>` from `r` and `tao`
    fields: list[tuple[str, str]]  # (ident, bound name) of the struct expression
    uses_tao: bool
    whole: str = ""  # a union's: the value `get` builds (its fields are set branch by branch)


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
    """The bits (a u64 expression) of value expression ``v`` of type ``t``."""
    rust = scalar(t)
    saturated = t.cast is CastMode.SATURATED
    if t.kind is PrimitiveKind.BOOL:
        return f"u64::from({v})"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return f"u64::from({WIRE}::f16_{'saturated' if saturated else 'truncated'}({v}))"
        return f"{v}.to_bits()" if rust == "f64" else f"u64::from({v}.to_bits())"
    full = t.bits == int(rust[1:])
    if t.kind is PrimitiveKind.UINT:
        value = v if rust == "u64" else f"u64::from({v})"
        return value if full or not saturated else f"{WIRE}::saturate_u({value}, {t.bits})"
    value = v if rust == "i64" else f"i64::from({v})"
    return f"{value} as u64" if full or not saturated else f"{WIRE}::saturate_i({value}, {t.bits})"


def _get_value(t: PrimitiveType) -> str:
    """The value of type ``t`` read from ``r``."""
    rust = scalar(t)
    raw = f"r.get({t.bits})?"
    if t.kind is PrimitiveKind.BOOL:
        return f"{raw} != 0"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return f"{WIRE}::f16_value({raw} as u16)"
        return f"f64::from_bits({raw})" if rust == "f64" else f"f32::from_bits({raw} as u32)"
    if t.kind is PrimitiveKind.UINT:
        return raw if rust == "u64" else f"{raw} as {rust}"
    signed = f"{WIRE}::sign_extend({raw}, {t.bits})"
    return signed if rust == "i64" else f"{signed} as {rust}"


def _zero(t: PrimitiveType) -> str:
    rust = scalar(t)
    return "false" if rust == "bool" else "0.0" if rust.startswith("f") else "0"


def dronecan_codec(schema: Schema, msg: Message, idents: dict[str, str]) -> DronecanCodec | None:
    """The codec of ``msg`` (None if it is not a DroneCAN message, or holds arrays of composites,
    which the bundled schemas do not). A union writes its tag (``union_tag``, in ceil(log2(fields))
    bits, as pydronecan) and then the one field it holds, told the union's own tail array flag; a
    tag naming no field is an error both ways."""
    info = msg.dronecan
    if info is None:
        return None
    if info.union:
        return _union(schema, msg, idents)
    put: list[str] = []
    get: list[str] = []
    bound: list[tuple[str, str]] = []
    uses_tao = False
    for n, f in enumerate(msg.fields):
        last = n == len(msg.fields) - 1
        tao = "tao" if last and _sensitive(schema, f.type) else "false"
        uses_tao = uses_tao or tao == "tao"
        if not _field(schema, f, idents, tao, put, get, bound):
            return None
    return DronecanCodec((info.max_bitlen + 7) // 8, put, get, bound, uses_tao)


def union_tag_bits(count: int) -> int:
    """pydronecan's tag width: ceil(log2(fields))."""
    return max(count - 1, 0).bit_length()


def _union(schema: Schema, msg: Message, idents: dict[str, str]) -> DronecanCodec | None:
    n = len(msg.fields)
    bits = union_tag_bits(n)
    wrong = f"{{ tag: usize::from(self.union_tag), fields: {n} }}"
    put = [f"if usize::from(self.union_tag) >= {n} {{", f"return Err({WIRE}::EncodeError::Tag {wrong});", "}"]
    put += [f"w.put(u64::from(self.union_tag), {bits});"] if bits else []
    get = ["let mut m = Self::new();"]
    if bits:
        get += [f"let tag = r.get({bits})? as usize;", f"if tag >= {n} {{"]
        get += [f"return Err({WIRE}::DecodeError::Tag {{ tag, fields: {n} }});", "}", "m.union_tag = tag as u8;"]
    else:
        get.append("let tag = 0;")
    uses_tao = False
    for k, f in enumerate(msg.fields):
        tao = "tao" if _sensitive(schema, f.type) else "false"
        uses_tao = uses_tao or tao == "tao"
        branch_put: list[str] = []
        branch_get: list[str] = []
        bound: list[tuple[str, str]] = []
        if not _field(schema, f, idents, tao, branch_put, branch_get, bound):
            return None
        head = "if" if k == 0 else "} else if"
        put += [f"{head} self.union_tag == {k} {{", *branch_put]
        get += [f"{head} tag == {k} {{", *branch_get, *(f"m.{ident} = {name};" for ident, name in bound)]
    if msg.fields:
        put.append("}")
        get.append("}")
    info = msg.dronecan
    assert info is not None
    return DronecanCodec((info.max_bitlen + 7) // 8, put, get, [], uses_tao, whole="m")


def _field(
    schema: Schema,
    f: Field,
    idents: dict[str, str],
    tao: str,
    put: list[str],
    get: list[str],
    bound: list[tuple[str, str]],
) -> bool:
    """The statements of one field (False: a type the Rust codec does not write)."""
    t = f.type
    if f.is_padding:
        assert isinstance(t, PrimitiveType)
        put.append(f"w.put(0, {t.bits});")
        get.append(f"r.get({t.bits})?;")
        return True
    ident = idents[f.name]
    name = f"f_{ident.strip('_')}"
    if isinstance(t, PrimitiveType):
        put.append(f"w.put({_put_value(t, f'self.{ident}')}, {t.bits});")
        get.append(f"let {name} = {_get_value(t)};")
        bound.append((ident, name))
        return True
    if isinstance(t, CompositeType):
        put.append(f"{WIRE}::Message::put(&self.{ident}, w, {tao})?;")
        get.append(f"let {name} = {WIRE}::Message::get(r, {tao})?;")
        bound.append((ident, name))
        return True
    # a string type or an array of composites: not in DroneCAN v0's battery messages
    return isinstance(t, ArrayType) and _array(schema, f, t, ident, name, tao, put, get, bound)


def _array(
    schema: Schema,
    f: Field,
    t: ArrayType,
    ident: str,
    name: str,
    tao: str,
    put: list[str],
    get: list[str],
    bound: list[tuple[str, str]],
) -> bool:
    el = t.element
    if not isinstance(el, PrimitiveType):
        return False
    cap = t.capacity or 0
    put_el = f"w.put({_put_value(el, 'v')}, {el.bits});"
    get_el = f"*e = {_get_value(el)};"
    if not t.dynamic:
        put += [f"for &v in &self.{ident} {{", put_el, "}"]
        get += [f"let mut {name} = [{_zero(el)}; {cap}];", f"for e in &mut {name} {{", get_el, "}"]
        bound.append((ident, name))
        return True
    width = cap.bit_length()
    length = f"self.{ident}_len"
    put += [
        f"if {length} > {cap} {{",
        f'return Err({WIRE}::EncodeError::Length {{ field: "{f.name}", length: {length}, capacity: {cap} }});',
        "}",
    ]
    count = f"w.put({length} as u64, {width});"
    tail = _eligible(schema, t) and tao == "tao"
    put += ["if !tao {", count, "}"] if tail else [count]
    put += [f"for &v in &self.{ident}[..{length}] {{", put_el, "}"]
    k = f"k_{name[2:]}"
    read_count = f"r.get({width})? as usize"
    if tail:
        get += [
            f"let {k} = if tao {{",
            f"let k = r.remaining() / {el.bits};",
            f"if r.remaining() - k * {el.bits} >= 8 {{",
            f'return Err({WIRE}::DecodeError::PartialElement {{ field: "{f.name}" }});',
            "}",
            "k",
            "} else {",
            read_count,
            "};",
        ]
    else:
        get.append(f"let {k} = {read_count};")
    get += [
        f"if {k} > {cap} {{",
        f'return Err({WIRE}::DecodeError::Length {{ field: "{f.name}", length: {k}, capacity: {cap} }});',
        "}",
        f"let mut {name} = [{_zero(el)}; {cap}];",
        f"for e in {name}.iter_mut().take({k}) {{",
        get_el,
        "}",
    ]
    bound += [(ident, name), (f"{ident}_len", k)]
    return True
