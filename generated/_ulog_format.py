# Copied by battgen from codegen/backends/python/runtime/_ulog_format.py; do not edit here, edit it there.
"""ULog formats: the file format's constants and C types, the 'F' record's format definitions
(:class:`Format`, :class:`Member`), their flattened byte layout (:class:`Layout`) and the format
of a generated uORB class (:func:`format_of`). Part of the ULog runtime that ``_ulog`` re-exports.
"""

from __future__ import annotations

import dataclasses
import struct
from collections.abc import Mapping
from typing import Any

from . import _uorb

MAGIC = b"ULog\x01\x12\x35"
VERSION = 1
SYNC = b"\x2f\x73\x13\x20\x25\x0c\xbb\x12"
INCOMPAT_DATA_APPENDED = 0x01  # bit 0 of incompat_flags[0]: data appended at appended_offsets
COMPAT_DEFAULT_PARAMETERS = 0x01  # bit 0 of compat_flags[0]: the log holds 'Q' records

# ULog C type -> (struct code, bytes, numpy type)
TYPES: dict[str, tuple[str, int, str]] = {
    "int8_t": ("b", 1, "i1"), "uint8_t": ("B", 1, "u1"), "int16_t": ("h", 2, "<i2"), "uint16_t": ("H", 2, "<u2"),
    "int32_t": ("i", 4, "<i4"), "uint32_t": ("I", 4, "<u4"), "int64_t": ("q", 8, "<i8"), "uint64_t": ("Q", 8, "<u8"),
    "float": ("f", 4, "<f4"), "double": ("d", 8, "<f8"), "bool": ("?", 1, "?"), "char": ("c", 1, "S1"),
}  # fmt: skip

HEAD = struct.Struct("<HB")  # a record's header: uint16 size, uint8 type
U16 = struct.Struct("<H")
U64 = struct.Struct("<Q")
MAX_DEPTH = 32  # nesting depth of formats, against cyclic definitions in a damaged log
# A ULog record's size is a uint16: no format can describe more bytes (nor array more elements), so a
# damaged or hostile format declaring more is refused before anything is laid out for it.
MAX_MESSAGE = 65535


class ULogError(ValueError):
    """A file that cannot be read as ULog, or a request the log cannot answer."""


class ULogWarning(UserWarning):
    """Damage the reader recovered from (truncated or corrupt records); also listed in Log.warnings."""


@dataclasses.dataclass(frozen=True)
class Member:
    """One field of a format: C type or nested format name, array length (0: scalar), name.

    Formats of generated classes also say which attribute holds the value (``attr``) and how
    (``kind``: scalar, char, string, bytes, array, nested, nested_array; '' for padding and for
    formats read from a log), with the ``nested`` format attached.
    """

    ctype: str
    count: int
    name: str
    attr: str = ""
    kind: str = ""
    nested: Format | None = None

    @property
    def is_padding(self) -> bool:
        return self.name.startswith("_padding")

    @property
    def type_text(self) -> str:
        return f"{self.ctype}[{self.count}]" if self.count else self.ctype

    def text(self) -> str:
        return f"{self.type_text} {self.name}"


@dataclasses.dataclass(frozen=True)
class Format:
    """A ULog format definition; for a generated class, also the class, its topics and version."""

    name: str
    members: tuple[Member, ...]
    cls: type[Any] | None = dataclasses.field(default=None, compare=False)
    topics: tuple[str, ...] = ()
    message_version: int | None = None

    def text(self) -> str:
        """The body of this format's 'F' record: ``name:type field;type field;``."""
        return self.name + ":" + "".join(m.text() + ";" for m in self.members)

    def renamed(self, name: str) -> Format:
        return dataclasses.replace(self, name=name)

    def formats(self) -> dict[str, Format]:
        """This format and every nested one, by name, nested formats first."""
        out: dict[str, Format] = {}
        for m in self.members:
            if m.nested is not None:
                for name, fmt in m.nested.formats().items():
                    if name in out and out[name].text() != fmt.text():
                        raise ULogError(f"two different formats named {name!r} in {self.name}")
                    out[name] = fmt
        out[self.name] = self
        return out


def parse_format(text: str) -> Format:
    """A format from the body of an 'F' record."""
    name, sep, body = text.partition(":")
    if not sep or not name:
        raise ULogError(f"format definition without 'name:': {text[:60]!r}")
    members = []
    for item in body.split(";"):
        if not item:
            continue
        ctype, _, field = item.strip().partition(" ")
        count = 0
        if "[" in ctype:
            ctype, _, rest = ctype.partition("[")
            if not rest.endswith("]") or not (rest[:-1].isascii() and rest[:-1].isdigit()):
                raise ULogError(f"format {name}: bad array type in {item!r}")
            if len(rest) > 6 or int(rest[:-1]) > MAX_MESSAGE:
                raise ULogError(
                    f"format {name}: array {item.strip()[:60]!r} is longer than a ULog message holds "
                    f"({MAX_MESSAGE} bytes)"
                )
            count = int(rest[:-1])
        if not field or not ctype:
            raise ULogError(f"format {name}: expected 'type name', got {item!r}")
        members.append(Member(ctype, count, field))
    return Format(name, tuple(members))


@dataclasses.dataclass(frozen=True)
class Layout:
    """A format flattened: one leaf per value (padding skipped), named as log tools do."""

    names: tuple[str, ...]
    codes: tuple[str, ...]
    offsets: tuple[int, ...]
    sizes: tuple[int, ...]
    np_types: tuple[str, ...]
    size: int  # bytes of the struct, padding included
    data_size: int  # bytes of a 'D' record's data: without the trailing top-level padding

    def columns(self) -> _uorb.Columns:
        fmt = _uorb.layout_format(self.codes, self.offsets, self.sizes)
        return _uorb.Columns(self.names, fmt, self.data_size, self.np_types, self.offsets)


def layout(fmt: Format, formats: Mapping[str, Format]) -> Layout:
    """Flatten ``fmt``, resolving nested types through ``formats`` (or the members' own)."""
    leaves: list[tuple[str, str, int, int, str]] = []
    size = _flatten(fmt, formats, "", 0, leaves, 0, [0])
    data_size = size
    for m in reversed(fmt.members):
        if not m.is_padding or m.ctype not in TYPES:
            break
        data_size -= TYPES[m.ctype][1] * max(m.count, 1)
    names, codes, offsets, sizes, np_types = zip(*leaves, strict=True) if leaves else ((), (), (), (), ())
    return Layout(names, codes, offsets, sizes, np_types, size, data_size)


def _flatten(
    fmt: Format, formats: Mapping[str, Format], prefix: str, base: int, out: list[tuple[str, str, int, int, str]],
    depth: int, visits: list[int],
) -> int:  # fmt: skip
    if depth > MAX_DEPTH:
        raise ULogError(f"format {fmt.name}: nested deeper than {MAX_DEPTH} levels (a cycle?)")
    at = base
    for m in fmt.members:
        n = max(m.count, 1)
        known = TYPES.get(m.ctype)
        if known is not None:
            code, width, np_type = known
            if at - base + width * n > MAX_MESSAGE:
                raise ULogError(f"format {fmt.name}: larger than a ULog message holds ({MAX_MESSAGE} bytes)")
            if not m.is_padding:
                if m.ctype == "char" and m.count:
                    out.append((prefix + m.name, f"{m.count}s", at, m.count, f"S{m.count}"))
                elif m.count:
                    out.extend((f"{prefix}{m.name}[{i}]", code, at + i * width, width, np_type) for i in range(n))
                else:
                    out.append((prefix + m.name, code, at, width, np_type))
            at += width * n
            continue
        sub = m.nested if m.nested is not None else formats.get(m.ctype)
        if sub is None:
            raise ULogError(f"format {fmt.name}: field {m.name} has unknown type {m.ctype!r}")
        for i in range(n):
            inner = f"{prefix}{m.name}[{i}]." if m.count else f"{prefix}{m.name}."
            at += _flatten(sub, formats, inner, at, out, depth + 1, visits)
            visits[0] += 1  # counted too: arrays of an empty nested type add no bytes
            if at - base > MAX_MESSAGE or visits[0] + len(out) > MAX_MESSAGE:
                raise ULogError(f"format {fmt.name}: larger than a ULog message holds ({MAX_MESSAGE} bytes)")
    return at - base


_CLASS_FORMATS: dict[type[Any], Format] = {}


def format_of(cls: type[Any]) -> Format:
    """A generated class's ULog format (cached)."""
    fmt = _CLASS_FORMATS.get(cls)
    if fmt is None:
        made = cls.ulog_format()
        if not isinstance(made, Format):
            raise ULogError(f"{cls.__name__}.ulog_format() did not return a Format")
        fmt = _CLASS_FORMATS[cls] = made
    return fmt
