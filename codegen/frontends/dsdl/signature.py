"""DSDL v0 signatures and bit lengths.

* CRC-64-WE (poly 0x42F0E1EBA9EA3693, init and xor-out all ones, not reflected; check value
  of "123456789" is 0x62EC59E3F1A4F00A) hashes the normalized definition into the DSDL signature.
* The normalized definition is the full name, then ``@union`` where declared, then one line per
  field (``<cast> <type> <name>``, ``voidN``, dynamic arrays as ``[<=N]``), halves of a service
  split by ``---``; constants, comments and blank lines do not take part.
* The data type signature starts from the DSDL signature (or OVERRIDE_SIGNATURE) and, for each
  field holding a composite (directly or as array elements), folds in that type's data type
  signature followed by the running value, both as 8 little-endian bytes.
"""

from __future__ import annotations

from collections.abc import Callable

from .definitions import ArrayT, AttrT, FieldDef, PrimT, RefT, Section, TypeDef, VoidT

MASK64 = (1 << 64) - 1
POLY = 0x42F0E1EBA9EA3693


def _make_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 56
        for _ in range(8):
            crc = ((crc << 1) ^ POLY) & MASK64 if crc & (1 << 63) else (crc << 1) & MASK64
        table.append(crc)
    return tuple(table)


_TABLE = _make_table()


class Crc64We:
    """Incremental CRC-64-WE; ``Crc64We(value)`` continues a hash whose result was ``value``."""

    def __init__(self, extend_from: int | None = None) -> None:
        self._crc = MASK64 if extend_from is None else (extend_from & MASK64) ^ MASK64

    def add(self, data: bytes) -> None:
        crc = self._crc
        for b in data:
            crc = ((crc << 8) & MASK64) ^ _TABLE[((crc >> 56) ^ b) & 0xFF]
        self._crc = crc

    @property
    def value(self) -> int:
        return self._crc ^ MASK64


def crc64we(data: bytes) -> int:
    crc = Crc64We()
    crc.add(data)
    return crc.value


def normalized_definition(td: TypeDef) -> str:
    lines = [td.full_name]
    for index, section in enumerate(td.sections):
        if index:
            lines.append("---")
        if section.union:
            lines.append("@union")
        lines.extend(f.normalized for f in section.fields)
    return "\n".join(lines)


def dsdl_signature(td: TypeDef) -> int:
    if td.override_signature is not None:
        return td.override_signature
    return crc64we(normalized_definition(td).encode("ascii"))


Lookup = Callable[[str], TypeDef]


def data_type_signature(td: TypeDef, lookup: Lookup, cache: dict[str, int]) -> int:
    """The signature nodes compare on the bus; ``cache`` memoises it per full name."""
    cached = cache.get(td.full_name)
    if cached is not None:
        return cached
    crc = Crc64We(dsdl_signature(td))
    for section in td.sections:
        for f in section.fields:
            ref = _composite(f.type)
            if ref is None:
                continue
            nested = data_type_signature(lookup(ref.full_name), lookup, cache)
            running = crc.value
            crc.add(nested.to_bytes(8, "little"))
            crc.add(running.to_bytes(8, "little"))
    cache[td.full_name] = crc.value
    return crc.value


def _composite(t: AttrT) -> RefT | None:
    if isinstance(t, RefT):
        return t
    if isinstance(t, ArrayT) and isinstance(t.element, RefT):
        return t.element
    return None


# --------------------------------------------------------------------------------------------
# Bit lengths.
#
# Plain values follow the reference tools: a dynamic array counts its length prefix in the
# maximum and counts as 0 bits in the minimum; a union adds a tag of bit_length(max(n-1, 1)).
# With tail array optimisation (``tao``), the last field of a structure (recursively through a
# trailing composite, static array element or union member) that is a dynamic array whose
# element is at least 8 bits long (by its minimum) is sent without its length prefix.


def union_tag_bits(count: int) -> int:
    return max(count - 1, 1).bit_length()


def length_prefix_bits(size: int) -> int:
    return size.bit_length()


def type_max_bits(t: AttrT, lookup: Lookup, tao: bool = False) -> int:
    if isinstance(t, PrimT | VoidT):
        return t.bits
    if isinstance(t, RefT):
        return section_max_bits(lookup(t.full_name).request, lookup, tao)
    inner = type_max_bits(t.element, lookup)
    last = type_max_bits(t.element, lookup, tao)
    if t.dynamic and tao and type_min_bits(t.element, lookup) >= 8:
        return t.size * inner
    prefix = length_prefix_bits(t.size) if t.dynamic else 0
    return prefix + (t.size - 1) * inner + last


def type_min_bits(t: AttrT, lookup: Lookup) -> int:
    if isinstance(t, PrimT | VoidT):
        return t.bits
    if isinstance(t, RefT):
        return section_min_bits(lookup(t.full_name).request, lookup)
    return 0 if t.dynamic else t.size * type_min_bits(t.element, lookup)


def section_max_bits(section: Section, lookup: Lookup, tao: bool = False) -> int:
    fields = section.fields
    if not fields:
        return 0
    if section.union:
        return union_tag_bits(len(fields)) + max(type_max_bits(f.type, lookup, tao) for f in fields)
    return sum(type_max_bits(f.type, lookup, tao and i == len(fields) - 1) for i, f in enumerate(fields))


def section_min_bits(section: Section, lookup: Lookup) -> int:
    """Minimum bits; tail array optimisation cannot lower it (dynamic arrays already count 0)."""
    fields: tuple[FieldDef, ...] = section.fields
    if not fields:
        return 0
    if section.union:
        return union_tag_bits(len(fields)) + min(type_min_bits(f.type, lookup) for f in fields)
    return sum(type_min_bits(f.type, lookup) for f in fields)
