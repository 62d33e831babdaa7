"""Static layout of a DroneCAN (UAVCAN v0) type for the codec generator.

A message body becomes a list of *items*: runs of fixed-size fields (a :class:`Segment`, whose
every bit position is known at generation time, nested fixed structures and short static arrays
flattened into it) and the variable parts in between (dynamic arrays, unions, nested structures of
variable size). A segment is read and written with one ``struct.Struct``: fields that start on a
byte boundary with a width of 8/16/32/64 bits map to their own struct code, the bytes holding the
others are read as little-endian integers and each field is assembled from shifted pieces.

The v0 bit order: the stream is most significant bit first; a field of more than 8 bits is
written least significant byte first, and a last partial byte keeps only its top bits.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .....ir import ArrayType, CastMode, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema

FLATTEN_LIMIT = 64  # static arrays of at most this many leaves are unrolled into a segment


@dataclass
class Leaf:
    """One primitive (or an aligned uint8 static array held as bytes) inside a segment."""

    label: str  # for errors: "BatteryInfo.status_flags"
    type: PrimitiveType
    enc: str  # expression of the value when encoding ("self.voltage")
    offset: int = 0  # bit offset inside the segment
    nbytes: int = 0  # > 0: a uint8 array of this many bytes starting on a byte boundary
    var: str = ""  # local holding the decoded value

    @property
    def bits(self) -> int:
        return self.nbytes * 8 if self.nbytes else self.type.bits

    @property
    def structable(self) -> bool:
        """Has a struct code of its own: starts on a byte and is a whole machine word."""
        if self.offset % 8:
            return False
        if self.nbytes:
            return True
        kind, bits = self.type.kind, self.type.bits
        if kind is PrimitiveKind.VOID:
            return bits % 8 == 0
        if kind is PrimitiveKind.FLOAT:
            return bits in (16, 32, 64)
        return kind in (PrimitiveKind.UINT, PrimitiveKind.INT) and bits in (8, 16, 32, 64)


@dataclass
class Node:
    """How decoded leaves are put back together into a field value."""

    leaf: Leaf | None = None
    items: list[Node] = field(default_factory=list)
    as_bytes: bool = False  # a list node building bytes
    factory: str = ""  # an object node: expression giving the class


@dataclass
class Segment:
    leaves: list[Leaf]
    nodes: list[tuple[int, Node]]  # (field index in the message, how to rebuild it)
    checks: list[tuple[str, int, str]]  # static arrays: (expression, length, label)
    bits: int = 0


@dataclass
class VarField:
    """A field of variable layout: dynamic array, union, big static array, variable structure."""

    index: int
    field_name: str
    ident: str
    type: FieldType
    last: bool  # the last field of its structure (tail array optimisation may apply)


Item = Segment | VarField


@dataclass
class Unit:
    """One struct code of a segment: a leaf of its own, padding, or an integer of group bytes."""

    start: int  # byte
    size: int  # bytes
    pack: str
    unpack: str
    leaf: Leaf | None = None
    group: bool = False


@dataclass
class Piece:
    """``size`` bits of a leaf's value from bit ``src`` sit at bit ``dst`` of group unit ``unit``."""

    unit: int
    src: int
    dst: int
    size: int


_UINT_CODES = {1: "B", 2: "H", 4: "I", 8: "Q"}
_INT_CODES = {1: "b", 2: "h", 4: "i", 8: "q"}


class Planner:
    def __init__(self, schema: Schema, factory: dict[str, str]) -> None:
        self.schema = schema
        self.messages = {m.qualified_name: m for m in schema.messages}
        self.member_idents: dict[str, list[str]] = {}
        self.factory = factory  # qualified name -> expression giving the class

    # -- sizes ----------------------------------------------------------------------------

    def message(self, t: CompositeType) -> Message:
        return self.messages[t.name]

    def min_bits(self, t: FieldType) -> int:
        """Minimum bit length as the reference counts it (dynamic arrays count 0)."""
        if isinstance(t, PrimitiveType):
            return t.bits
        if isinstance(t, ArrayType):
            return 0 if t.dynamic else (t.capacity or 0) * self.min_bits(t.element)
        if isinstance(t, CompositeType):
            info = self.message(t).dronecan
            return info.min_bitlen if info is not None else 0
        raise TypeError(t)

    def tao_eligible(self, t: ArrayType) -> bool:
        return t.dynamic and self.min_bits(t.element) >= 8

    def fixed(self, t: FieldType) -> bool:
        """Laid out at known bit positions (so it can join a segment)."""
        if isinstance(t, PrimitiveType):
            return True
        if isinstance(t, ArrayType):
            return not t.dynamic and self.fixed(t.element) and self.leaf_count(t) <= FLATTEN_LIMIT
        if isinstance(t, CompositeType):
            m = self.message(t)
            if m.dronecan is None or m.dronecan.union:
                return False
            return all(self.fixed(f.type) for f in m.fields)
        return False

    def leaf_count(self, t: FieldType) -> int:
        if isinstance(t, PrimitiveType):
            return 1
        if isinstance(t, ArrayType):
            n = t.capacity or 0
            if is_u8(t.element):
                return 1
            return n * self.leaf_count(t.element)
        if isinstance(t, CompositeType):
            return sum(self.leaf_count(f.type) for f in self.message(t).fields)
        return 1

    def fixed_bits(self, t: FieldType) -> int:
        if isinstance(t, PrimitiveType):
            return t.bits
        if isinstance(t, ArrayType):
            return (t.capacity or 0) * self.fixed_bits(t.element)
        if isinstance(t, CompositeType):
            return sum(self.fixed_bits(f.type) for f in self.message(t).fields)
        raise TypeError(t)

    def tao_sensitive(self, t: FieldType) -> bool:
        """Whether the encoding of ``t`` depends on the tail array optimisation flag it gets."""
        if isinstance(t, PrimitiveType):
            return False
        if isinstance(t, ArrayType):
            return self.tao_eligible(t) or self.tao_sensitive(t.element)
        if isinstance(t, CompositeType):
            m = self.message(t)
            if m.dronecan is not None and m.dronecan.union:
                return any(self.tao_sensitive(f.type) for f in m.fields)
            return bool(m.fields) and self.tao_sensitive(m.fields[-1].type)
        return False

    # -- items ----------------------------------------------------------------------------

    def items(self, msg: Message, cls: str, idents: list[str], base: str) -> list[Item]:
        """The body of ``msg``: segments and variable fields, in wire order."""
        out: list[Item] = []
        seg: Segment | None = None
        last_index = len(msg.fields) - 1
        for i, f in enumerate(msg.fields):
            if self.fixed(f.type):
                if seg is None:
                    seg = Segment([], [], [])
                    out.append(seg)
                label = f"{cls}.{f.name}" if not f.is_padding else f"{cls}.<void>"
                expr = f"{base}.{idents[i]}" if idents[i] else "0"
                node = self.flatten(seg, f.type, expr, label)
                if not f.is_padding:
                    seg.nodes.append((i, node))
            else:
                seg = None
                out.append(VarField(i, f.name, idents[i], f.type, i == last_index))
        return out

    def flatten(self, seg: Segment, t: FieldType, expr: str, label: str) -> Node:
        if isinstance(t, PrimitiveType):
            leaf = Leaf(label, t, expr, seg.bits)
            seg.leaves.append(leaf)
            seg.bits += t.bits
            return Node(leaf=leaf)
        if isinstance(t, ArrayType):
            n = t.capacity or 0
            seg.checks.append((expr, n, label))
            if is_u8(t.element) and seg.bits % 8 == 0:
                assert isinstance(t.element, PrimitiveType)
                leaf = Leaf(label, t.element, expr, seg.bits, nbytes=n)
                seg.leaves.append(leaf)
                seg.bits += 8 * n
                return Node(leaf=leaf)
            items = [self.flatten(seg, t.element, f"{expr}[{k}]", f"{label}[{k}]") for k in range(n)]
            return Node(items=items, as_bytes=is_u8(t.element))
        assert isinstance(t, CompositeType)
        m = self.message(t)
        children = []
        for f in m.fields:
            sub = self.flatten(
                seg, f.type, "0" if f.is_padding else f"{expr}.{self.ident(m, f.name)}", f"{label}.{f.name}"
            )
            if not f.is_padding:
                children.append(sub)
        return Node(items=children, factory=self.factory[t.name])

    def ident(self, m: Message, name: str) -> str:
        return self.idents(m)[[f.name for f in m.fields].index(name)]

    def idents(self, m: Message) -> list[str]:
        from ...naming import member_names, module_classes, module_path

        cached = self.member_idents.get(m.qualified_name)
        if cached is None:
            names = member_names(m, module_classes(self.schema, module_path(m)))
            cached = ["" if f.is_padding else names[("field", f.name)] for f in m.fields]
            self.member_idents[m.qualified_name] = cached
        return cached


def is_u8(t: FieldType) -> bool:
    return isinstance(t, PrimitiveType) and t.kind is PrimitiveKind.UINT and t.bits == 8


def struct_code(t: PrimitiveType, *, pack: bool) -> str:
    """The struct code of a whole-word primitive (pack: what the encoder hands struct)."""
    size = t.bits // 8
    if t.kind is PrimitiveKind.FLOAT:
        return {2: "H" if pack else "e", 4: "f", 8: "d"}[size]
    if t.kind is PrimitiveKind.INT and (not pack or t.cast is CastMode.SATURATED):
        return _INT_CODES[size]
    return _UINT_CODES[size]


def plan_units(seg: Segment) -> tuple[list[Unit], dict[int, list[Piece]]]:
    """Split a segment's bytes into struct units; pieces of every leaf that lives in group bytes."""
    nbytes = (seg.bits + 7) // 8
    starts = {leaf.offset // 8: leaf for leaf in seg.leaves if leaf.structable}
    units: list[Unit] = []
    byte = 0
    while byte < nbytes:
        leaf = starts.get(byte)
        if leaf is not None:
            size = leaf.bits // 8
            if leaf.nbytes:
                units.append(Unit(byte, size, f"{size}s", f"{size}s", leaf))
            elif leaf.type.kind is PrimitiveKind.VOID:
                units.append(Unit(byte, size, f"{size}x", f"{size}x"))
            else:
                units.append(
                    Unit(byte, size, struct_code(leaf.type, pack=True), struct_code(leaf.type, pack=False), leaf)
                )
            byte += size
            continue
        end = byte
        while end < nbytes and end not in starts:
            end += 1
        while byte < end:
            size = max(s for s in (8, 4, 2, 1) if s <= end - byte)
            units.append(Unit(byte, size, _UINT_CODES[size], _UINT_CODES[size], group=True))
            byte += size
    unit_of_byte = {}
    for k, u in enumerate(units):
        for b in range(u.start, u.start + u.size):
            unit_of_byte[b] = k
    pieces: dict[int, list[Piece]] = {}
    for idx, leaf in enumerate(seg.leaves):
        if leaf.structable or leaf.type.kind is PrimitiveKind.VOID:
            continue
        runs: list[Piece] = []
        for b in range(leaf.bits):
            stream = leaf.offset + stream_index(b, leaf.bits)
            k = unit_of_byte[stream // 8]
            dst = 8 * (stream // 8 - units[k].start) + 7 - stream % 8
            prev = runs[-1] if runs else None
            if prev is not None and prev.unit == k and prev.src + prev.size == b and prev.dst + prev.size == dst:
                prev.size += 1
            else:
                runs.append(Piece(k, b, dst, 1))
        pieces[idx] = runs
    return units, pieces


def stream_index(b: int, width: int) -> int:
    """Position in the stream (from the field's first bit) of value bit ``b`` of a ``width``-bit field."""
    chunk = b // 8
    length = min(8, width - 8 * chunk)
    return 8 * chunk + length - 1 - (b - 8 * chunk)


def reorder_terms(width: int) -> list[tuple[int, int, int]]:
    """(value shift, mask, stream shift) terms turning a value into its stream bits (MSB first)."""
    terms = []
    for chunk in range((width + 7) // 8):
        length = min(8, width - 8 * chunk)
        terms.append((8 * chunk, (1 << length) - 1, width - 8 * chunk - length))
    return terms
