"""MAVLink wire facts derived from IR fields: C type names, wire order, lengths, CRC_EXTRA.

Computed here independently of pymavlink (the conformance tests compare the two), following
the MAVLink spec: base fields are sent sorted by element size, largest first (stable), then
extension fields in definition order; CRC_EXTRA folds the CRC-16/MCRF4XX of
"NAME " + for each base field in wire order "type name " (+ array length byte) into one byte.
"""

from __future__ import annotations

from collections.abc import Sequence

from ...ir import ArrayType, Field, FieldType, PrimitiveKind, PrimitiveType, StringType

_FLOAT_NAMES = {32: "float", 64: "double"}


def c_type(ftype: FieldType) -> tuple[str, int]:
    """(C element type name as MAVLink XML spells it, array length or 0 for a scalar)."""
    if isinstance(ftype, StringType):
        return "char", ftype.capacity or 0
    if isinstance(ftype, ArrayType) and isinstance(ftype.element, PrimitiveType):
        return c_type(ftype.element)[0], ftype.capacity or 0
    if isinstance(ftype, PrimitiveType):
        if ftype.kind is PrimitiveKind.CHAR:
            return "char", 0
        if ftype.kind is PrimitiveKind.FLOAT:
            return _FLOAT_NAMES[ftype.bits], 0
        prefix = "u" if ftype.kind is PrimitiveKind.UINT else ""
        return f"{prefix}int{ftype.bits}_t", 0
    raise TypeError(f"not a MAVLink field type: {ftype!r}")


def element_size(ftype: FieldType) -> int:
    if isinstance(ftype, StringType):
        return 1
    if isinstance(ftype, ArrayType) and isinstance(ftype.element, PrimitiveType):
        return ftype.element.bits // 8
    if isinstance(ftype, PrimitiveType):
        return ftype.bits // 8
    raise TypeError(f"not a MAVLink field type: {ftype!r}")


def wire_size(ftype: FieldType) -> int:
    return element_size(ftype) * max(1, c_type(ftype)[1])


def wire_order(fields: Sequence[Field]) -> list[Field]:
    base = [f for f in fields if not f.extension]
    # sorted() is stable, so equal sizes keep definition order
    return sorted(base, key=element_size_of, reverse=True) + [f for f in fields if f.extension]


def element_size_of(f: Field) -> int:
    return element_size(f.type)


def lengths(fields: Sequence[Field]) -> tuple[int, int]:
    """(payload bytes without extensions, payload bytes with them)."""
    base = sum(wire_size(f.type) for f in fields if not f.extension)
    return base, base + sum(wire_size(f.type) for f in fields if f.extension)


def crc16_mcrf4xx(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16/MCRF4XX (poly 0x1021 reflected, init 0xFFFF, no final xor): MAVLink's checksum."""
    for byte in data:
        tmp = (byte ^ crc) & 0xFF
        tmp = (tmp ^ (tmp << 4)) & 0xFF
        crc = ((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4)) & 0xFFFF
    return crc


def crc_extra(name: str, fields: Sequence[Field]) -> int:
    crc = crc16_mcrf4xx(f"{name} ".encode("ascii"))
    for f in wire_order(fields):
        if f.extension:
            continue  # extensions may be added later without breaking old receivers
        type_name, length = c_type(f.type)
        crc = crc16_mcrf4xx(f"{type_name} {f.name} ".encode("ascii"), crc)
        if length:
            crc = crc16_mcrf4xx(bytes([length]), crc)
    return (crc & 0xFF) ^ (crc >> 8)
