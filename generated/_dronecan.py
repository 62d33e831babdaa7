# Copied by battgen from codegen/backends/python/runtime/_dronecan.py; do not edit here, edit it there.
"""Run-time support of the generated DroneCAN (UAVCAN v0) codecs. Standard library only.

The generated code writes a message as one Python int, most significant bit first, behind a
sentinel 1 bit (so the bit count is ``acc.bit_length() - 1``); it reads from one int of the
whole payload, counting the bits that remain after the read position.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

from ._meta import DataError

_F32 = struct.Struct("<f")
_U32 = struct.Struct("<I")
_F64 = struct.Struct("<d")
_U64 = struct.Struct("<Q")
_E16 = struct.Struct("<e")
_U16 = struct.Struct("<H")

F16_MAX = 65504.0
F32_MAX = 3.4028234663852886e38
INF = float("inf")

T = TypeVar("T")


class DecodeError(ValueError):
    """Bytes that are not a valid encoding: names the field and what was wrong."""


class EncodeError(ValueError):
    """A value that cannot be encoded (an array longer than its capacity, an unknown union field)."""


UNION_ATTR = "union_field"


class Union:
    """The branches of one generated union class, and the rules that keep exactly one of them held.

    A union object holds its value in the attribute of the selected branch; every other branch
    attribute is None, and ``union_field`` names the selected branch by its DSDL name (as
    pydronecan's ``get_active_union_field``). Assigning a value to a branch selects it; assigning
    a branch's name to ``union_field`` switches to that branch with a fresh default value (from the
    class's ``_dc_zero(name)``).
    """

    __slots__ = ("attrs", "names", "owner")

    def __init__(self, owner: str, branches: tuple[tuple[str, str], ...]) -> None:
        self.owner = owner
        self.names: dict[str, str] = dict(branches)  # DSDL name -> attribute
        self.attrs: dict[str, str] = {attr: name for name, attr in branches}  # attribute -> DSDL name

    @staticmethod
    def _zero(obj: Any, name: str) -> Any:
        return obj._dc_zero(name)

    def settle(self, obj: object) -> None:
        """``__post_init__``: the one branch given to the constructor, or the first at its default."""
        held = [name for name, attr in self.names.items() if getattr(obj, attr) is not None]
        if len(held) > 1:
            raise TypeError(f"{self.owner}: a union holds one field, got {', '.join(held)}")
        if held:
            name = held[0]
        else:
            name = next(iter(self.names))
            object.__setattr__(obj, self.names[name], self._zero(obj, name))
        object.__setattr__(obj, UNION_ATTR, name)

    def assign(self, obj: object, attr: str, value: object) -> None:
        """``__setattr__``: a value given to a branch selects it and drops the others."""
        if attr == UNION_ATTR:
            self.switch(obj, value)
            return
        object.__setattr__(obj, attr, value)
        name = self.attrs.get(attr)
        if name is None or value is None:
            return
        try:
            current = getattr(obj, UNION_ATTR)
        except AttributeError:  # still inside __init__: settle() checks that one branch was given
            return
        if current != name:
            self._drop_others(obj, name)
            object.__setattr__(obj, UNION_ATTR, name)

    def switch(self, obj: object, name: object) -> None:
        """``union_field = name``: select that branch, at its default unless it already holds a value.

        A name that is no branch is stored as it is; ``validate()`` reports it and ``encode()`` refuses it."""
        if isinstance(name, str) and name in self.names:
            attr = self.names[name]
            if getattr(obj, attr, None) is None:
                object.__setattr__(obj, attr, self._zero(obj, name))
            self._drop_others(obj, name)
        object.__setattr__(obj, UNION_ATTR, name)

    def _drop_others(self, obj: object, name: str) -> None:
        for other, attr in self.names.items():
            if other != name:
                object.__setattr__(obj, attr, None)

    def choose(self, obj: object, data: Mapping[str, Any]) -> None:
        """``from_dict``: the branch the plain data names (``union_field``, or its one branch key)."""
        given = [name for name in self.names if name in data]
        tag = data.get(UNION_ATTR)
        choices = ", ".join(self.names)
        if UNION_ATTR in data:
            if not isinstance(tag, str) or tag not in self.names:
                raise DataError(f"{self.owner}.{UNION_ATTR}", f"one of {choices}", tag)
            if given and given != [tag]:
                raise DataError(f"{self.owner}.{UNION_ATTR}", f"the branch the data gives ({given[0]})", tag)
            self.switch(obj, tag)
        elif len(given) > 1:
            raise DataError(self.owner, f"one field of the union ({choices})", given)


def f16bits(u: int) -> int:
    """float16 bits of the float32 with bits ``u``, rounded as the reference does."""
    sign = (u >> 16) & 0x8000
    a = u & 0x7FFFFFFF
    if a >= 0x7F800000:  # inf or NaN; every NaN becomes 0x7FFF
        return sign | (0x7FFF if a > 0x7F800000 else 0x7C00)
    if a >= 0x38800000:  # normal half (or overflow): drop 13 bits, a set bit 12 rounds up
        h = (a - 0x37FFF000) >> 13
        return sign | (h if h < 0x7C00 else 0x7C00)
    # subnormal half: the reference scales the float32 (low 12 bits cleared) by 2**-112,
    # which rounds to nearest even into a float32 subnormal, then rounds that half up.
    a &= 0xFFFFF000
    e = a >> 23
    if e == 0:
        return sign
    sig = 0x800000 | (a & 0x7FFFFF)
    shift = 113 - e
    if shift > 24:
        return sign
    m = sig >> shift
    rest = sig & ((1 << shift) - 1)
    half = 1 << (shift - 1)
    if rest > half or (rest == half and m & 1):
        m += 1
    return sign | ((m + 0x1000) >> 13)


def f16s(x: float) -> int:
    """Bits of a saturated float16: a finite value out of range clamps to +-65504; infinity and NaN
    are kept (the DSDL v0 rule, "infinity will be preserved", as libuavcan's FloatSpec::saturate and
    pydronecan's re-encoding of decoded data; only pydronecan's value setter clamps infinity too)."""
    if F16_MAX < x < INF:
        x = F16_MAX
    elif -INF < x < -F16_MAX:
        x = -F16_MAX
    u: int = _U32.unpack(_F32.pack(x))[0]
    a = u & 0x7FFFFFFF
    if 0x38800000 <= a < 0x477FF000:
        return ((u >> 16) & 0x8000) | ((a - 0x37FFF000) >> 13)
    return f16bits(u)


def f16bits_saturated(u: int) -> int:
    """float16 bits of a saturated field from the float32 bits ``u`` of its value as given: beyond +-65504 (and
    short of infinity) it is +-65504, else as :func:`f16bits` (the cut the encoders leave the uncommon halves to)."""
    if 0x477FF000 <= u & 0x7FFFFFFF < 0x7F800000:
        return ((u >> 16) & 0x8000) | 0x7BFF
    return f16bits(u)


def float32_bits(count: int, truncated: tuple[int, ...] = ()) -> Callable[..., tuple[int, ...]]:
    """A function giving the float32 bit patterns of ``count`` float16 field values in one struct round trip;
    an encoder cuts each half out of them: a positive normal half is a subtraction and a shift, the rest is
    :func:`f16bits_saturated`'s or :func:`f16bits`'s. A saturated value beyond +-65504 is left for the cut to
    clamp (one beyond float32's range is clamped here); the values at the positions ``truncated`` become
    infinity beyond +-65504 first, as a truncated field's do."""
    pack = struct.Struct(f"<{count}f").pack
    unpack = struct.Struct(f"<{count}I").unpack
    if truncated:

        def cast_bits(*values: float) -> tuple[int, ...]:
            cast = [f16_truncated(x) if i in truncated else f16_saturated(x) for i, x in enumerate(values)]
            return unpack(pack(*cast))

        return cast_bits

    def bits(*values: float) -> tuple[int, ...]:
        try:
            return unpack(pack(*values))
        except OverflowError:  # beyond float32: of such a value a saturated float16 keeps +-65504
            return unpack(pack(*map(f16_saturated, values)))

    return bits


def f16_saturated(x: float) -> float:
    """A saturated float16 field's value before rounding: a finite value beyond +-65504 clamps to it;
    infinity and NaN are kept (as :func:`f16s`)."""
    if F16_MAX < x < INF:
        return F16_MAX
    if -INF < x < -F16_MAX:
        return -F16_MAX
    return x


def f16_truncated(x: float) -> float:
    """A truncated float16 field's value before rounding: beyond +-65504 it is infinity (as :func:`f16t`)."""
    if x > F16_MAX:
        return INF
    if x < -F16_MAX:
        return -INF
    return x


def f16t(x: float) -> int:
    """Bits of a truncated float16: a value beyond +-65504 becomes infinity (before rounding, as the
    reference casts); NaN is kept."""
    if x > F16_MAX:
        x = INF
    elif x < -F16_MAX:
        x = -INF
    return f16bits(_U32.unpack(_F32.pack(x))[0])


def f16v(bits: int) -> float:
    """Value of float16 bits (exact, as the reference converts them)."""
    return float(_E16.unpack(_U16.pack(bits))[0])


def f32bits(x: float) -> int:
    return int(_U32.unpack(_F32.pack(x))[0])


def f32v(bits: int) -> float:
    return float(_F32.unpack(_U32.pack(bits))[0])


def f64bits(x: float) -> int:
    return int(_U64.unpack(_F64.pack(x))[0])


def f64v(bits: int) -> float:
    return float(_F64.unpack(_U64.pack(bits))[0])


def finish(acc: int) -> bytes:
    """The bytes of a sentinel-led bit accumulator, zero padded to a whole byte."""
    n = acc.bit_length() - 1
    pad = -n & 7
    return ((acc ^ (1 << n)) << pad).to_bytes((n + pad) >> 3, "big")


def cut(table: tuple[tuple[int, str], ...], have: int) -> DecodeError:
    """The error for a fixed run of fields cut short: names the first field that does not fit."""
    for end, label in table:
        if end > have:
            return DecodeError(f"{label}: input ends inside this field ({have} bits left, {end} needed)")
    return DecodeError(f"{table[-1][1]}: input ends inside this field")


def beyond(owner: str, extra: int) -> DecodeError:
    """The error for ``extra`` bytes after the end of a message."""
    return DecodeError(f"{owner}: {extra} byte(s) beyond the end of the message")


def read(cls: type[T], data: bytes, tao: bool) -> T:
    """A whole payload read by the type's bit reader ``_dc_get`` (``decode`` for what it does not read itself:
    a union, a payload with fields of varying size before its end, a tail array without TAO)."""
    get: Callable[[int, int, bool], tuple[T, int]] = getattr(cls, "_dc_get")  # noqa: B009 (generated, unknown to T)
    obj, rem = get(int.from_bytes(data, "big"), len(data) << 3, tao)
    if rem >= 8:
        raise beyond(cls.__name__, rem >> 3)
    return obj


def short(label: str, need: int, have: int) -> DecodeError:
    return DecodeError(f"{label}: input ends inside this field ({have} bits left, {need} needed)")


def stream(value: int, width: int) -> int:
    """The ``width``-bit unsigned ``value`` in stream order (DSDL v0: low byte first, a last partial byte
    keeping only its top bits)."""
    out = 0
    for chunk in range((width + 7) // 8):
        length = min(8, width - 8 * chunk)
        out |= ((value >> (8 * chunk)) & ((1 << length) - 1)) << (width - 8 * chunk - length)
    return out


def unstream(bits: int, width: int) -> int:
    """The value of ``width`` bits read in stream order (the inverse of :func:`stream`)."""
    out = 0
    for chunk in range((width + 7) // 8):
        length = min(8, width - 8 * chunk)
        out |= ((bits >> (width - 8 * chunk - length)) & ((1 << length) - 1)) << (8 * chunk)
    return out


def put_bytes(acc: int, value: bytes, capacity: int, tail: bool, label: str) -> int:
    """``acc`` followed by a dynamic uint8 array: its length in ``capacity.bit_length()`` bits, unless it is
    the tail array sent with TAO (``tail``), then its bytes."""
    k = len(value)
    if k > capacity:
        raise EncodeError(f"{label}: length {k} exceeds capacity {capacity}")
    if not tail:
        width = capacity.bit_length()
        acc = (acc << width) | stream(k, width)
    return (acc << (k << 3)) | int.from_bytes(value, "big")


def get_bytes(v: int, rem: int, capacity: int, tail: bool, label: str) -> tuple[bytes, int]:
    """A dynamic uint8 array read from payload int ``v`` with ``rem`` bits left, and the bits left after it:
    the tail array sent with TAO (``tail``) is every whole byte that is left, any other has its length first."""
    if tail:
        k = rem >> 3
    else:
        width = capacity.bit_length()
        if rem < width:
            raise short(f"{label} (length)", width, rem)
        rem -= width
        k = unstream((v >> rem) & ((1 << width) - 1), width)
    if k > capacity:
        raise DecodeError(f"{label}: length {k} exceeds capacity {capacity}")
    need = k << 3
    if rem < need:
        raise short(label, need, rem)
    rem -= need
    return ((v >> rem) & ((1 << need) - 1)).to_bytes(k, "big"), rem


def _crc_table() -> tuple[int, ...]:
    out = []
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
        out.append(crc)
    return tuple(out)


_CRC = _crc_table()


def crc16(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16-CCITT (polynomial 0x1021, no reflection), continuing from ``crc``."""
    table = _CRC
    for byte in data:
        crc = ((crc << 8) & 0xFF00) ^ table[(crc >> 8) ^ byte]
    return crc


def transfer_crc(signature: int, payload: bytes) -> int:
    """The CRC of a multi-frame transfer: CRC-16-CCITT over the data type signature
    (8 bytes, little-endian) followed by the payload."""
    return crc16(payload, crc16(signature.to_bytes(8, "little")))
