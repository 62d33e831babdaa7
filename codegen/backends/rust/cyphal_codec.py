"""The crate's Cyphal (UAVCAN v1) types: one module per Cyphal namespace (``cyphal::reg::udral::service::
battery``), a struct per type (``Status0_2``: the name and version, as Rust's type names allow) with its
constants and its ``cyphal_wire::Message`` implementation. The statements spell out per type the rules
the Python runtime ``_cyphal.py`` walks (pydsdl's ``serialize``): bits least significant first, a
composite (and an array of them) at a byte, no tail array optimisation, a variable-length array behind
its length prefix, a union behind its tag, a nested delimited type behind its delimiter header
(``put_nested`` / ``get_nested``), float16 rounded to nearest even, casts as each field's cast mode says."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import jinja2

from ...ir import ArrayType, CastMode, CompositeType, Field, FieldType, Message, PrimitiveKind, PrimitiveType, Schema
from ...ir import SourceFormat as Fmt
from .docs import doc_text
from .naming import camel, field_ident, snake, upper
from .types import scalar, scalar_literal

WIRE = "cyphal_wire"


def length_bits(capacity: int) -> int:
    """The width of a variable-length array's length prefix (pydsdl's ``length_field_type``)."""
    return next(bits for bits in (8, 16, 32, 64) if capacity.bit_length() <= bits)


def module_of(msg: Message) -> tuple[str, ...]:
    """``cyphal.uavcan.si.unit.voltage.Scalar_1_0`` -> ``("cyphal", "uavcan", "si", "unit", "voltage")``."""
    return tuple(snake(part) for part in msg.qualified_name.split(".")[:-1])


def struct_name(msg: Message) -> str:
    """``Scalar_1_0`` -> ``Scalar1_0``; the service marker ``_.0.1`` takes its namespace's name."""
    base, major, minor = msg.name.rsplit("_", 2)
    if base.strip("_") == "":
        base = msg.qualified_name.split(".")[-2]
    return f"{camel(base)}{major}_{minor}"


def rust_path(schema: Schema, name: str) -> str:
    msg = schema.message(name)
    return "crate::" + "::".join(module_of(msg)) + "::" + struct_name(msg)


def _aligned(t: FieldType) -> bool:
    if isinstance(t, ArrayType):
        return _aligned(t.element)
    return isinstance(t, CompositeType)


def _put_value(t: PrimitiveType, v: str) -> str:
    """The bits (a u64 expression) of value expression ``v``; an f32 or f64 is within its own range, so
    only float16 has a cast to apply."""
    rust = scalar(t)
    saturated = t.cast is CastMode.SATURATED
    if t.kind is PrimitiveKind.BOOL:
        return f"u64::from({v})"
    if t.kind is PrimitiveKind.FLOAT:
        if t.bits == 16:
            return f"u64::from({WIRE}::f16_bits({v}, {'true' if saturated else 'false'}))"
        return f"{v}.to_bits()" if rust == "f64" else f"u64::from({v}.to_bits())"
    full = t.bits == int(rust[1:])
    if t.kind is PrimitiveKind.UINT:
        value = v if rust == "u64" else f"u64::from({v})"
        return value if full or not saturated else f"{WIRE}::saturate_u({value}, {t.bits})"
    value = v if rust == "i64" else f"i64::from({v})"
    return f"{value} as u64" if full or not saturated else f"{WIRE}::saturate_i({value}, {t.bits})"


def _get_value(t: PrimitiveType) -> str:
    rust = scalar(t)
    raw = f"r.get({t.bits})"
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


@dataclass
class _Member:
    ident: str
    rust: str
    default: str
    doc: str
    length: str = ""  # a variable-length array's count field


class _Type:
    """One type's struct and statements."""

    def __init__(self, schema: Schema, msg: Message) -> None:
        self.schema = schema
        self.msg = msg
        self.put: list[str] = []
        self.get: list[str] = []
        self.members: list[_Member] = []

    def rust_type(self, t: FieldType) -> tuple[str, str]:
        """(Rust type, its zero value) of a field type."""
        if isinstance(t, PrimitiveType):
            rust = scalar(t)
            return rust, "false" if rust == "bool" else "0.0" if rust.startswith("f") else "0"
        if isinstance(t, CompositeType):
            path = rust_path(self.schema, t.name)
            return path, f"{path}::new()"
        assert isinstance(t, ArrayType), t
        inner, zero = self.rust_type(t.element)
        return f"[{inner}; {t.capacity or 0}]", f"[{zero}; {t.capacity or 0}]"

    def field(self, f: Field) -> None:
        t = f.type
        if f.is_padding:
            assert isinstance(t, PrimitiveType)
            self.put.append(f"w.skip({t.bits});")
            self.get.append(f"r.skip({t.bits});")
            return
        ident = field_ident(f.name)
        rust, zero = self.rust_type(t)
        dynamic = isinstance(t, ArrayType) and t.dynamic
        doc = doc_text(" ".join(part for part in (f"[{f.unit_text}]" if f.unit_text else "", f.doc) if part))
        self.members.append(_Member(ident, rust, zero, doc, f"{ident}_len" if dynamic else ""))
        if _aligned(t):
            self.put.append("w.align();")
            self.get.append("r.align();")
        if isinstance(t, PrimitiveType):
            self.put.append(f"w.put({_put_value(t, f'self.{ident}')}, {t.bits});")
            self.get.append(f"m.{ident} = {_get_value(t)};")
        elif isinstance(t, CompositeType):
            self.put.append(f"self.{ident}.put_nested(w)?;")
            self.get.append(f"m.{ident} = {WIRE}::Message::get_nested(r)?;")
        else:
            assert isinstance(t, ArrayType), t
            self.array(f, t, ident)

    def array(self, f: Field, t: ArrayType, ident: str) -> None:
        cap = t.capacity or 0
        el = t.element
        if isinstance(el, CompositeType):
            put_el, get_el = "v.put_nested(w)?;", f"*e = {WIRE}::Message::get_nested(r)?;"
            each = "for v in "
        else:
            assert isinstance(el, PrimitiveType), el
            put_el, get_el = f"w.put({_put_value(el, 'v')}, {el.bits});", f"*e = {_get_value(el)};"
            each = "for &v in "
        if not t.dynamic:
            self.put += [f"{each}&self.{ident} {{", put_el, "}"]
            self.get += [f"for e in &mut m.{ident} {{", get_el, "}"]
            return
        bits = length_bits(cap)
        length = f"self.{ident}_len"
        self.put += [
            f"if {length} > {cap} {{",
            f'return Err({WIRE}::EncodeError::Length {{ field: "{f.name}", length: {length}, capacity: {cap} }});',
            "}",
            f"w.put({length} as u64, {bits});",
            f"{each}&self.{ident}[..{length}] {{",
            put_el,
            "}",
        ]
        self.get += [
            f"let n = r.get({bits}) as usize;",
            f"if n > {cap} {{",
            f'return Err({WIRE}::DecodeError::Length {{ field: "{f.name}", length: n, capacity: {cap} }});',
            "}",
            f"m.{ident}_len = n;",
            f"for e in m.{ident}.iter_mut().take(n) {{",
            get_el,
            "}",
        ]

    def build(self) -> dict[str, object]:
        msg = self.msg
        info = msg.cyphal
        assert info is not None, msg.qualified_name
        if info.union:
            n = len(msg.fields)
            bits = info.union_tag_bits
            wrong = f"{{ tag: usize::from(self.union_tag), fields: {n} }}"
            self.put += [
                f"if usize::from(self.union_tag) >= {n} {{",
                f"return Err({WIRE}::EncodeError::Tag {wrong});",
                "}",
                f"w.put(u64::from(self.union_tag), {bits});",
            ]
            self.get += [
                f"let tag = r.get({bits}) as usize;",
                f"if tag >= {n} {{",
                f"return Err({WIRE}::DecodeError::Tag {{ tag, fields: {n} }});",
                "}",
                "m.union_tag = tag as u8;",
            ]
            for k, f in enumerate(msg.fields):
                head = "if" if k == 0 else "} else if"
                self.put.append(f"{head} self.union_tag == {k} {{")
                self.get.append(f"{head} tag == {k} {{")
                self.field(f)
            self.put.append("}")
            self.get.append("}")
            held = "The field held, by its place; the others are not sent."
            self.members.insert(0, _Member("union_tag", "u8", "0", held))
        else:
            for f in msg.fields:
                self.field(f)
        name = struct_name(msg)
        constants = [
            {
                "name": upper(c.name),
                "rust": scalar(c.type),
                "value": scalar_literal(c.type, c.value),
                "doc": doc_text(c.doc),
            }
            for c in msg.constants
            if isinstance(c.type, PrimitiveType)
        ]
        return {
            "name": name,
            "qualified": msg.qualified_name,
            "full_name": f"{info.full_name}.{info.major}.{info.minor}",
            "doc": doc_text(msg.doc),
            "members": self.members,
            "constants": constants,
            "put_lines": self.put,
            "get_lines": self.get,
            "mutable": any(line.startswith("m.") or "&mut m." in line for line in self.get),
            "max_bytes": (info.max_bitlen + 7) // 8,
            "extent_bytes": info.extent // 8,
            "sealed": "true" if info.sealed else "false",
            "port": "None" if info.fixed_port_id is None else f"Some({info.fixed_port_id})",
        }


def cyphal_modules(schema: Schema, env: jinja2.Environment) -> dict[str, str]:
    """Relative path -> text (before rustfmt) of every Cyphal module of the crate: a file per namespace
    holding its types, and the ``mod.rs`` of each namespace above them (none without Cyphal types)."""
    by_module: dict[tuple[str, ...], list[dict[str, object]]] = defaultdict(list)
    for msg in schema.messages:
        if msg.format is Fmt.CYPHAL:
            by_module[module_of(msg)].append(_Type(schema, msg).build())
    if not by_module:
        return {}
    files: dict[str, str] = {}
    children: dict[tuple[str, ...], set[str]] = defaultdict(set)
    template = env.get_template("cyphal.rs.j2")
    for parts, types in sorted(by_module.items()):
        files["src/" + "/".join(parts) + ".rs"] = template.render(path="::".join(parts), types=types)
        for i in range(1, len(parts)):
            children[parts[:i]].add(parts[i])
    module = env.get_template("mod.rs.j2")
    for parts, subs in sorted(children.items()):
        files["src/" + "/".join(parts) + "/mod.rs"] = module.render(
            path="::".join(parts),
            name=parts[-1],
            what="the Cyphal types of this namespace" if len(parts) > 1 else "the Cyphal (UAVCAN v1) types",
            modules=sorted(subs),
            reexports=[],
        )
    return files
