"""Reading a flattened devicetree blob (.dtb, devicetree specification v0.4 chapter 5).

Layout: a 40-byte big-endian header, the memory reservation block (u64 address/size pairs
ending with 0/0), the structure block (u32 tokens) and the strings block (property names).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from .model import DevicetreeError, DtNode, DtValue

MAGIC = 0xD00DFEED
FDT_BEGIN_NODE, FDT_END_NODE, FDT_PROP, FDT_NOP, FDT_END = 1, 2, 3, 4, 9
_HEADER = struct.Struct(">10I")
READABLE_VERSIONS = range(16, 18)  # v16 and v17 blobs; v17 is what dtc writes


@dataclass(frozen=True)
class Blob:
    nodes: list[DtNode]
    reservations: list[tuple[int, int]]
    version: int
    boot_cpuid: int


def parse_dtb(data: bytes, display: str) -> Blob:
    def fail(offset: int, message: str) -> DevicetreeError:
        return DevicetreeError(display, 0, f"byte {offset:#x}: {message}")

    if len(data) < 4:
        raise fail(0, f"blob of {len(data)} bytes is too short: expected a devicetree blob header")
    magic = int.from_bytes(data[:4], "big")
    if magic != MAGIC:
        raise fail(0, f"magic {magic:#010x}: expected {MAGIC:#010x} (not a .dtb file)")
    if len(data) < 28:
        raise fail(len(data), "truncated header: expected at least 28 bytes")
    fields = list(_HEADER.unpack_from(data.ljust(40, b"\0")))
    _, total, off_struct, off_strings, off_rsv, version, last_comp, boot_cpuid, size_strings, size_struct = fields
    if version < 16 or last_comp > 17:
        raise fail(0x14, f"version {version} (compatible with {last_comp}): expected a version 16 or 17 blob")
    header_size = 40 if version >= 17 else 36
    if len(data) < header_size:
        raise fail(len(data), f"truncated header: expected {header_size} bytes")
    if total > len(data):
        raise fail(len(data), f"truncated blob: header says {total} bytes, file has {len(data)}")
    if version < 17:
        size_struct = total - off_struct
    for name, off, size in (("structure", off_struct, size_struct), ("strings", off_strings, size_strings)):
        if off < header_size or off + size > total:
            raise fail(off, f"{name} block {off:#x}+{size:#x} lies outside the {total}-byte blob")
    if off_rsv < header_size or off_rsv % 8 or off_rsv >= total:
        raise fail(off_rsv, "memory reservation block offset: expected an 8-byte aligned offset inside the blob")
    blob = data[:total]
    strings = blob[off_strings : off_strings + size_strings]

    reservations: list[tuple[int, int]] = []
    pos = off_rsv
    while True:
        if pos + 16 > total:
            raise fail(pos, "memory reservation block runs off the blob: expected a 0/0 terminator")
        address, size = struct.unpack_from(">QQ", blob, pos)
        pos += 16
        if address == 0 and size == 0:
            break
        reservations.append((address, size))

    end = off_struct + size_struct
    nodes: list[DtNode] = []
    stack: list[DtNode] = []
    pos = off_struct

    def u32(at: int) -> int:
        if at + 4 > end:
            raise fail(at, "structure block ends inside a token: expected 4 more bytes")
        return int.from_bytes(blob[at : at + 4], "big")

    def cstring(buf: bytes, at: int, limit: int, what: str) -> str:
        stop = buf.find(b"\0", at, limit)
        if stop < 0:
            raise fail(at, f"{what} has no terminating NUL")
        try:
            return buf[at:stop].decode("ascii")
        except UnicodeDecodeError:
            raise fail(at, f"{what} is not ASCII") from None

    while True:
        token = u32(pos)
        token_at = pos
        pos += 4
        if token == FDT_BEGIN_NODE:
            name = cstring(blob, pos, end, "node name")
            pos = _align(pos + len(name) + 1)
            if not stack and nodes:
                raise fail(token_at, "a second root node: expected FDT_END")
            if not stack and name:
                raise fail(token_at, f"root node named {name!r}: expected an empty name")
            parent = stack[-1].path if stack else ""
            path = "/" if not stack else f"{'' if parent == '/' else parent}/{name}"
            node = DtNode(path, {}, (), 0, display)
            nodes.append(node)
            stack.append(node)
        elif token == FDT_END_NODE:
            if not stack:
                raise fail(token_at, "FDT_END_NODE without an open node")
            stack.pop()
        elif token == FDT_PROP:
            length, nameoff = u32(pos), u32(pos + 4)
            pos += 8
            if not stack:
                raise fail(token_at, "property outside any node")
            if nameoff >= len(strings):
                raise fail(token_at, f"property name offset {nameoff} lies outside the strings block")
            pname = cstring(strings, nameoff, len(strings), "property name")
            if pos + length > end:
                raise fail(pos, f"property {pname!r} of {length} bytes runs off the structure block")
            if pname in stack[-1].properties:
                raise fail(token_at, f"property {pname!r} twice in {stack[-1].path}")
            stack[-1].properties[pname] = DtValue(bytes(blob[pos : pos + length]), (), 0, display)
            pos = _align(pos + length)
        elif token == FDT_NOP:
            continue
        elif token == FDT_END:
            if stack:
                raise fail(token_at, f"FDT_END with node {stack[-1].path} still open: expected FDT_END_NODE")
            break
        else:
            raise fail(token_at, f"unknown structure token {token:#x}: expected 1, 2, 3, 4 or 9")
    if not nodes:
        raise fail(off_struct, "no root node in the structure block")
    return Blob(nodes, reservations, version, boot_cpuid)


def _align(pos: int) -> int:
    return (pos + 3) & ~3
