"""The devicetree instance model shared by the .dts parser and the .dtb reader.

A node keeps each property as the bytes a blob would hold (so a .dts and its compiled .dtb read
into equal nodes) plus, for source input, how the value was written (``parts``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import SchemaError


class DevicetreeError(SchemaError):
    """Unreadable devicetree input (.dts/.dtsi/.dtb): names the file, the line and what was expected.

    For a .dtb there are no lines: ``line`` is 0 and the message gives the byte offset.
    """


@dataclass(frozen=True)
class DtPart:
    """One comma-separated piece of a source value: ``kind`` is "string", "cells" (``bits`` wide),
    "bytes" or "path" (a ``&label`` outside cells, stored as the node's path string)."""

    kind: str
    value: str | bytes | tuple[int, ...]
    bits: int = 0


@dataclass(frozen=True)
class DtValue:
    """A property value: the raw big-endian bytes, and typed views of them."""

    data: bytes
    parts: tuple[DtPart, ...] = ()  # empty for .dtb input (a blob does not record how it was written)
    line: int = 0
    file: str = ""

    @property
    def is_flag(self) -> bool:
        return not self.data

    def strings(self) -> list[str] | None:
        """The NUL-separated UTF-8 strings, or None when the bytes are not a string list."""
        if not self.data.endswith(b"\0"):
            return None
        try:
            return self.data[:-1].decode("utf-8").split("\0")
        except UnicodeDecodeError:
            return None

    def cells(self, bits: int = 32, signed: bool = False) -> list[int] | None:
        """The value as ``bits``-wide big-endian integers, or None when the length does not divide."""
        size = bits // 8
        if size not in (1, 2, 4, 8) or len(self.data) % size:
            return None
        return [int.from_bytes(self.data[i : i + size], "big", signed=signed) for i in range(0, len(self.data), size)]

    def guess(self) -> str:
        """How dtc would print the value: "flag", "strings", "cells" or "bytes"."""
        if not self.data:
            return "flag"
        strings = self.strings()
        if strings is not None and all(s and s.isprintable() for s in strings):
            return "strings"
        return "cells" if len(self.data) % 4 == 0 else "bytes"


@dataclass
class DtNode:
    """One node of a devicetree, in document order (the root first)."""

    path: str
    properties: dict[str, DtValue] = field(default_factory=dict)
    labels: tuple[str, ...] = ()
    line: int = 0
    file: str = ""

    @property
    def name(self) -> str:
        return "/" if self.path == "/" else self.path.rsplit("/", 1)[-1]

    @property
    def label(self) -> str | None:
        return self.labels[0] if self.labels else None

    @property
    def phandle(self) -> int | None:
        value = self.properties.get("phandle") or self.properties.get("linux,phandle")
        cells = value.cells() if value is not None else None
        return cells[0] if cells and len(cells) == 1 else None

    @property
    def compatible(self) -> list[str]:
        value = self.properties.get("compatible")
        return (value.strings() or []) if value is not None else []

    def raw(self) -> dict[str, bytes]:
        """Property name -> bytes: what a .dts and its .dtb must agree on."""
        return {k: v.data for k, v in self.properties.items()}
