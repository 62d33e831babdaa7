"""The uORB C struct of a message, flattened for code generation.

The frontend computed PX4's layout (``UorbInfo.layout``: fields sorted by element size with
``_paddingN`` slots); this module turns it into what the generated code needs: one ``struct``
format for the whole struct with nested messages inlined, how many unpacked values each field
takes, the ULog type of each slot, and flattened column names as PX4 log tools spell them
(``voltage_cell_v[3]``, ``previous.lat``).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass

from ....errors import BattgenError
from ....ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema, StringType

# struct code, ULog C type and numpy type of each uORB builtin
_BUILTINS: dict[tuple[PrimitiveKind, int], tuple[str, str, str]] = {
    (PrimitiveKind.BOOL, 8): ("?", "bool", "?"),
    (PrimitiveKind.CHAR, 8): ("c", "char", "S1"),
    (PrimitiveKind.INT, 8): ("b", "int8_t", "i1"),
    (PrimitiveKind.UINT, 8): ("B", "uint8_t", "u1"),
    (PrimitiveKind.INT, 16): ("h", "int16_t", "<i2"),
    (PrimitiveKind.UINT, 16): ("H", "uint16_t", "<u2"),
    (PrimitiveKind.INT, 32): ("i", "int32_t", "<i4"),
    (PrimitiveKind.UINT, 32): ("I", "uint32_t", "<u4"),
    (PrimitiveKind.INT, 64): ("q", "int64_t", "<i8"),
    (PrimitiveKind.UINT, 64): ("Q", "uint64_t", "<u8"),
    (PrimitiveKind.FLOAT, 32): ("f", "float", "<f4"),
    (PrimitiveKind.FLOAT, 64): ("d", "double", "<f8"),
}


def builtin(t: PrimitiveType, where: str) -> tuple[str, str, str]:
    """(struct code, ULog C type, numpy type) of a builtin element."""
    try:
        return _BUILTINS[(t.kind, 8 if t.kind is PrimitiveKind.BOOL else t.bits)]
    except KeyError:
        raise BattgenError(f"{where}: type {t.name} has no uORB encoding") from None


def snake(name: str) -> str:
    """PX4's struct/format name for a message: ``BatteryStatusV0`` -> ``battery_status_v0``
    (the rule the uORB frontend applies for default topic names)."""
    spaced = re.sub(r"(.)([A-Z][a-z]+)", r"\1_\2", name)
    return re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", spaced).lower()


@dataclass(frozen=True)
class Part:
    """One slot of a message's struct as generated code handles it.

    ``kind``: ``pad`` (padding bytes), ``scalar``, ``char`` (one char), ``string`` (char[N]),
    ``bytes`` (uint8[N], a ``bytes`` attribute), ``array`` (other builtin arrays, a list),
    ``nested`` and ``nested_array`` (other messages, inlined). ``values`` counts the items this
    slot contributes to the unpacked tuple of the message's struct.
    """

    name: str
    kind: str
    offset: int
    size: int
    code: str = ""  # struct code of the slot ('f', '14f', '40s', '3x'); '' for nested kinds
    ctype: str = ""  # ULog type of one element (uint8_t, float, char, a nested format name)
    count: int = 0  # ULog array length (0 for scalars)
    values: int = 0
    nested: Message | None = None


def _element(t: FieldType) -> tuple[FieldType, int]:
    if isinstance(t, ArrayType):
        if t.dynamic or not t.capacity:
            raise BattgenError(f"uORB arrays have a fixed length, got {t}")
        return t.element, t.capacity
    return t, 0


def parts(schema: Schema, msg: Message) -> list[Part]:
    """The slots of ``msg`` in struct order (PX4's layout), padding included."""
    info = msg.uorb
    if info is None:
        raise BattgenError(f"{msg.qualified_name}: no uORB layout")
    out: list[Part] = []
    expected = 0
    for slot in info.layout:
        if slot.offset != expected:
            raise BattgenError(f"{msg.qualified_name}: layout gap before {slot.name} at offset {slot.offset}")
        expected = slot.offset + slot.size
        if slot.field is None:
            out.append(Part(slot.name, "pad", slot.offset, slot.size, f"{slot.size}x", "uint8_t", slot.size))
            continue
        where = f"{msg.qualified_name}.{slot.field}"
        ftype = msg.field(slot.field).type
        if isinstance(ftype, StringType):
            n = ftype.capacity or 0
            out.append(Part(slot.field, "string", slot.offset, slot.size, f"{n}s", "char", n, 1))
            continue
        element, count = _element(ftype)
        if isinstance(element, CompositeType):
            nested = schema.message(element.name)
            kind = "nested_array" if count else "nested"
            values = count_values(schema, nested) * max(count, 1)
            ctype = snake(nested.name)
            out.append(Part(slot.field, kind, slot.offset, slot.size, "", ctype, count, values, nested))
            continue
        if not isinstance(element, PrimitiveType):
            raise BattgenError(f"{where}: unsupported uORB element type")
        code, ctype, _ = builtin(element, where)
        if not count:
            kind = "char" if element.kind is PrimitiveKind.CHAR else "scalar"
            out.append(Part(slot.field, kind, slot.offset, slot.size, code, ctype, 0, 1))
        elif element.kind is PrimitiveKind.UINT and element.bits == 8:
            out.append(Part(slot.field, "bytes", slot.offset, slot.size, f"{count}s", ctype, count, 1))
        else:
            out.append(Part(slot.field, "array", slot.offset, slot.size, f"{count}{code}", ctype, count, count))
    if expected != info.struct_size:
        raise BattgenError(f"{msg.qualified_name}: layout ends at {expected}, struct size is {info.struct_size}")
    return out


def count_values(schema: Schema, msg: Message) -> int:
    return sum(p.values for p in parts(schema, msg))


def codes(schema: Schema, msg: Message) -> Iterator[str]:
    """Struct codes of the whole struct, nested messages inlined (one code per slot)."""
    for p in parts(schema, msg):
        if p.nested is not None:
            for _ in range(max(p.count, 1)):
                yield from codes(schema, p.nested)
        else:
            yield p.code


def trailing_padding(schema: Schema, msg: Message) -> int:
    """Bytes of top-level padding at the end: PX4's logger leaves them out of ULog records."""
    last = parts(schema, msg)[-1]
    return last.size if last.kind == "pad" else 0


def struct_format(schema: Schema, msg: Message, *, trailing: bool = True) -> str:
    """'<'-prefixed struct format of the message (with or without the trailing padding)."""
    items = list(codes(schema, msg))
    if not trailing and trailing_padding(schema, msg):
        items.pop()
    return "<" + compress(items)


def compress(items: list[str]) -> str:
    """Join codes, merging runs of one single-letter code ('f','f','f' -> '3f'; '2x','6x' -> '8x')."""
    runs: list[tuple[int, str]] = []
    for item in items:
        n, code = (int(item[:-1]), item[-1]) if item[:-1] else (1, item)
        if runs and code == runs[-1][1] and code not in "s":
            runs[-1] = (runs[-1][0] + n, code)
        else:
            runs.append((n, code))
    return "".join(f"{n}{c}" if n != 1 or c == "s" else c for n, c in runs)


@dataclass(frozen=True)
class Column:
    """One column of batch decoding: a flattened name, its struct code, byte offset and numpy type."""

    name: str
    code: str
    offset: int
    size: int
    np_type: str


def columns(schema: Schema, msg: Message, prefix: str = "", base: int = 0) -> Iterator[Column]:
    """Every value of the struct as a column, named as PX4 log tools flatten ULog data."""
    for p in parts(schema, msg):
        at = base + p.offset
        if p.kind == "pad":
            continue
        if p.kind == "string":
            yield Column(prefix + p.name, p.code, at, p.size, f"S{p.count}")
            continue
        if p.nested is not None:
            element = p.size // max(p.count, 1)
            if p.count:
                for i in range(p.count):
                    yield from columns(schema, p.nested, f"{prefix}{p.name}[{i}].", at + i * element)
            else:
                yield from columns(schema, p.nested, f"{prefix}{p.name}.", at)
            continue
        ftype = msg.field(p.name).type
        element_type, _ = _element(ftype)
        assert isinstance(element_type, PrimitiveType)
        code, _, np_type = builtin(element_type, p.name)
        width = p.size // max(p.count, 1)
        if p.count:
            for i in range(p.count):
                yield Column(f"{prefix}{p.name}[{i}]", code, at + i * width, width, np_type)
        else:
            yield Column(prefix + p.name, code, at, width, np_type)


def column_format(cols: list[Column], size: int) -> str:
    """Struct format reading exactly ``cols`` (gaps skipped as padding) from a ``size``-byte record."""
    items: list[str] = []
    at = 0
    for c in cols:
        if c.offset > at:
            items.append(f"{c.offset - at}x")
        items.append(c.code)
        at = c.offset + c.size
    if size > at:
        items.append(f"{size - at}x")
    return "<" + compress(items)
