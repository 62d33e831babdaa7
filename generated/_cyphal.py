# Copied by battgen from codegen/backends/python/runtime/_cyphal.py; do not edit here, edit it there.
"""Run-time support of the generated Cyphal (UAVCAN v1) codecs. Standard library only.

Cyphal's wire rules (the specification's section 3.7, as pydsdl's ``serialize`` applies them): bits fill
each byte from its least significant bit, a multi-byte value is little-endian, a composite (and an array of
composites) starts at a byte boundary and ends padded to one; an array's length and a union's tag are
unsigned prefixes; a delimited (non-``@sealed``) type nested in another is preceded by its length in bytes
(``uint32``), so a reader that knows an older, shorter version skips what it does not know. A top-level
object has no such header: the transfer's length bounds it.

Each generated class describes its fields once, as a :class:`Struct` of specs, and this module walks it:
one interpreter rather than code per type keeps the rules in one place, where a test can hold them against
pydsdl's. A spec is a tuple whose first item names its kind:

* ``("b",)`` bool; ``("u", bits, saturated)``, ``("i", bits, saturated)``, ``("f", bits, saturated)``;
  ``("v", bits)`` padding;
* ``("a", element, capacity, length_bits)`` an array (``length_bits`` 0 when its length is fixed), held as a
  list; ``("y", capacity, length_bits)`` an array of ``uint8`` / ``byte`` / ``utf8``, held as ``bytes``;
* ``("c", factory)`` a composite, ``factory()`` giving its generated class (whose ``CYPHAL_STRUCT`` is its
  :class:`Struct`); late, so that classes may refer to each other across modules.

Reading follows the specification's implicit zero extension: bits past the end of the data read as zero,
and bytes left over after the last field are ignored (an extent larger than the type's own size).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from typing import Any

_FORMATS = {16: struct.Struct("<e"), 32: struct.Struct("<f"), 64: struct.Struct("<d")}
# the saturation bounds of float16/32/64: the largest finite value of each (as pydsdl's value ranges)
_FLOAT_MAX = {16: 65504.0, 32: 3.4028234663852886e38, 64: 1.7976931348623157e308}
DELIMITER_BITS = 32

Spec = tuple[Any, ...]


class DecodeError(ValueError):
    """Bytes that are not a valid serialization: names the field and what was wrong."""


class EncodeError(ValueError):
    """A value that cannot be serialized (an array longer than its capacity, a union holding no branch)."""


class Struct:
    """How one composite type is laid out: its fields in order, sealed or delimited, union or structure.

    ``fields`` pairs each field's attribute (``""`` for padding) with its spec; ``union_tag_bits`` is 0 for a
    structure and the width of the tag of a union (whose held branch is the object's ``union_field``)."""

    __slots__ = ("extent_bytes", "fields", "name", "sealed", "union_tag_bits")

    def __init__(
        self, name: str, fields: tuple[tuple[str, Spec], ...], *, sealed: bool, extent_bytes: int, union_tag_bits: int
    ) -> None:
        self.name = name
        self.fields = fields
        self.sealed = sealed
        self.extent_bytes = extent_bytes
        self.union_tag_bits = union_tag_bits


class _Writer:
    """Bits gathered into one int, the first bit written its least significant."""

    __slots__ = ("acc", "n")

    def __init__(self) -> None:
        self.acc = 0
        self.n = 0

    def put(self, value: int, bits: int) -> None:
        self.acc |= (value & ((1 << bits) - 1)) << self.n
        self.n += bits

    def align(self, bits: int) -> None:
        self.n += -self.n % bits  # zero padding: nothing to or in

    def data(self) -> bytes:
        return self.acc.to_bytes((self.n + 7) >> 3, "little")


class _Reader:
    """Bits read from one int holding ``end`` bits; past ``end`` every bit reads as zero."""

    __slots__ = ("data", "end", "pos")

    def __init__(self, data: int, end: int) -> None:
        self.data = data
        self.end = end
        self.pos = 0

    def get(self, bits: int) -> int:
        value = (self.data >> self.pos) & ((1 << bits) - 1)
        self.pos += bits
        return value

    def align(self, bits: int) -> None:
        self.pos += -self.pos % bits

    def sub(self, bits: int) -> _Reader:
        """A reader of the next ``bits`` bits (a delimited object), which this one then skips."""
        inner = _Reader((self.data >> self.pos) & ((1 << bits) - 1), bits)
        self.pos += bits
        return inner


def alignment(spec: Spec) -> int:
    """A composite starts at a byte; an array where its element does; every other value at any bit."""
    kind = spec[0]
    if kind == "c":
        return 8
    if kind == "a":
        return alignment(spec[1])
    return 1


def struct_of(cls: Any) -> Struct:
    layout: Struct = cls.CYPHAL_STRUCT
    return layout


# ---- writing -------------------------------------------------------------------------------------------


def encode(obj: object, layout: Struct, *, with_delimiter_header: bool = False) -> bytes:
    """The serialization of ``obj``; with its delimiter header only when asked (a top-level object has none)."""
    if with_delimiter_header and layout.sealed:
        raise EncodeError(f"{layout.name} is sealed: it has no delimiter header")
    w = _Writer()
    _put_object(w, obj, layout)
    data = w.data()
    if with_delimiter_header:
        return len(data).to_bytes(DELIMITER_BITS // 8, "little") + data
    return data


def _put_object(w: _Writer, obj: object, layout: Struct) -> None:
    if layout.union_tag_bits:
        held = getattr(obj, "union_field", None)
        for index, (attr, spec) in enumerate(layout.fields):
            if attr == held or (held is None and getattr(obj, attr) is not None):
                w.put(index, layout.union_tag_bits)
                _put(w, getattr(obj, attr), spec, f"{layout.name}.{attr}")
                break
        else:
            raise EncodeError(f"{layout.name}: the union holds no field ({held!r})")
    else:
        for attr, spec in layout.fields:
            w.align(alignment(spec))
            if spec[0] == "v":
                w.n += spec[1]
            else:
                _put(w, getattr(obj, attr), spec, f"{layout.name}.{attr}")
    w.align(8)


def _put(w: _Writer, value: Any, spec: Spec, label: str) -> None:
    kind = spec[0]
    if kind == "u" or kind == "i":
        w.put(int_bits(int(value), spec[1], spec[2], kind == "i"), spec[1])
    elif kind == "f":
        w.put(float_bits(float(value), spec[1], spec[2]), spec[1])
    elif kind == "b":
        w.put(1 if value else 0, 1)
    elif kind == "y":
        data = bytes(value)
        _put_length(w, len(data), spec[1], spec[2], label)
        w.put(int.from_bytes(data, "little"), 8 * len(data))
    elif kind == "a":
        items = list(value)
        _put_length(w, len(items), spec[2], spec[3], label)
        element = spec[1]
        for index, item in enumerate(items):
            w.align(alignment(element))
            _put(w, item, element, f"{label}[{index}]")
    elif kind == "c":
        layout = struct_of(spec[1]())
        w.align(8)
        if layout.sealed:
            _put_object(w, value, layout)
        else:  # its own bytes first, to know the length the header gives
            inner = _Writer()
            _put_object(inner, value, layout)
            w.put(inner.n >> 3, DELIMITER_BITS)
            w.put(inner.acc, inner.n)
    else:  # pragma: no cover - the generator writes only the kinds above
        raise EncodeError(f"{label}: unknown spec {spec!r}")


def _put_length(w: _Writer, length: int, capacity: int, length_bits: int, label: str) -> None:
    if length_bits == 0:
        if length != capacity:
            raise EncodeError(f"{label}: expected exactly {capacity} elements, got {length}")
        return
    if length > capacity:
        raise EncodeError(f"{label}: expected at most {capacity} elements, got {length}")
    w.put(length, length_bits)


def int_bits(value: int, bits: int, saturated: bool, signed: bool) -> int:
    """The two's complement bits of an integer: clamped to the type's range when saturated, else its low bits
    (a truncated cast, as the specification defines it)."""
    if saturated:
        low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
        value = low if value < low else high if value > high else value
    return value & ((1 << bits) - 1)


def float_bits(value: float, bits: int, saturated: bool) -> int:
    """IEEE 754 bits of a float of ``bits`` (rounded to nearest even). A saturated cast clamps a finite value
    to the largest finite one (infinity and NaN kept); a truncated one lets it overflow to infinity."""
    if saturated and math.isfinite(value):
        top = _FLOAT_MAX[bits]
        value = -top if value < -top else top if value > top else value
    fmt = _FORMATS[bits]
    try:
        packed = fmt.pack(value)
    except OverflowError:  # beyond the format's range after rounding: infinity of that sign
        packed = fmt.pack(math.copysign(math.inf, value))
    return int.from_bytes(packed, "little")


# ---- reading -------------------------------------------------------------------------------------------


def decode(cls: Callable[[], Any], data: bytes, layout: Struct, *, with_delimiter_header: bool = False) -> Any:
    """An object of ``cls`` read from ``data`` (with a leading delimiter header when asked)."""
    raw = bytes(data)
    r = _Reader(int.from_bytes(raw, "little"), 8 * len(raw))
    if with_delimiter_header:
        if layout.sealed:
            raise DecodeError(f"{layout.name} is sealed: it has no delimiter header")
        r = _delimited(r, layout.name)
    return _get_object(r, cls, layout)


def _delimited(r: _Reader, name: str) -> _Reader:
    size = r.get(DELIMITER_BITS)
    left = max(0, r.end - r.pos)
    if 8 * size > left:
        raise DecodeError(f"{name}: the delimiter header gives {size} bytes, {left // 8} remain")
    return r.sub(8 * size)


def _get_object(r: _Reader, cls: Callable[[], Any], layout: Struct) -> Any:
    obj = cls()
    if layout.union_tag_bits:
        tag = r.get(layout.union_tag_bits)
        if tag >= len(layout.fields):
            raise DecodeError(f"{layout.name}: union tag {tag}, expected below {len(layout.fields)}")
        attr, spec = layout.fields[tag]
        setattr(obj, attr, _get(r, spec, f"{layout.name}.{attr}"))
    else:
        for attr, spec in layout.fields:
            r.align(alignment(spec))
            if spec[0] == "v":
                r.pos += spec[1]
            else:
                setattr(obj, attr, _get(r, spec, f"{layout.name}.{attr}"))
    r.align(8)
    return obj


def _get(r: _Reader, spec: Spec, label: str) -> Any:
    kind = spec[0]
    if kind == "u":
        return r.get(spec[1])
    if kind == "i":
        bits = spec[1]
        value = r.get(bits)
        return value - (1 << bits) if value >> (bits - 1) else value
    if kind == "f":
        bits = spec[1]
        return float(_FORMATS[bits].unpack(r.get(bits).to_bytes(bits >> 3, "little"))[0])
    if kind == "b":
        return bool(r.get(1))
    if kind == "y":
        length = _get_length(r, spec[1], spec[2], label)
        return r.get(8 * length).to_bytes(length, "little")
    if kind == "a":
        length = _get_length(r, spec[2], spec[3], label)
        element = spec[1]
        out = []
        for index in range(length):
            r.align(alignment(element))
            out.append(_get(r, element, f"{label}[{index}]"))
        return out
    if kind == "c":
        cls = spec[1]()
        layout = struct_of(cls)
        r.align(8)
        if layout.sealed:
            return _get_object(r, cls, layout)
        return _get_object(_delimited(r, label), cls, layout)
    raise DecodeError(f"{label}: unknown spec {spec!r}")  # pragma: no cover - never generated


def _get_length(r: _Reader, capacity: int, length_bits: int, label: str) -> int:
    if length_bits == 0:
        return capacity
    length = r.get(length_bits)
    if length > capacity:
        raise DecodeError(f"{label}: array length {length}, expected at most {capacity}")
    return length
