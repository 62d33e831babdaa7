"""The frame-level facts of DroneCAN (UAVCAN v0): the 29-bit CAN identifier, the tail byte, the transfer CRC.

The identifier (UAVCAN v0 specification, "CAN bus transport layer"):

- bits 28..24 priority; bit 7 service-not-message; bits 6..0 source node id;
- message frame: bits 23..8 the 16-bit data type id;
- anonymous message frame (source node 0): bits 23..10 a discriminator, bits 9..8 the data type id's low 2 bits;
- service frame: bits 23..16 the 8-bit data type id, bit 15 request-not-response, bits 14..8 destination node.

The last byte of every frame is the tail byte: start of transfer (bit 7), end of transfer (bit 6), toggle (bit 5)
and the 5-bit transfer id. A multi-frame transfer starts with a 16-bit little-endian CRC of its payload: CRC-16-CCITT
(polynomial 0x1021, no reflection) whose initial value is the CRC of the data type signature's 8 little-endian bytes
(itself computed from 0xFFFF), so that a payload read with the wrong data type fails the check.
"""

from __future__ import annotations

import binascii
from dataclasses import dataclass

PRIORITY_SHIFT = 24
SERVICE_BIT = 0x80
ID_MASK = 0x1FFFFFFF
TAIL_START = 0x80
TAIL_END = 0x40
TAIL_TOGGLE = 0x20
TRANSFER_ID_MASK = 0x1F
TRANSFER_IDS = 32
CLASSIC_DATA = 8  # bytes of a classic CAN frame, the tail byte included
FD_DATA = 64


def crc16(data: bytes, initial: int = 0xFFFF) -> int:
    """CRC-16-CCITT (poly 0x1021, initial 0xFFFF unless given, no reflection, no final xor): the standard library's
    ``binascii.crc_hqx`` is exactly this CRC, in C."""
    return binascii.crc_hqx(data, initial)


def signature_crc(signature: int) -> int:
    """The initial value of a transfer CRC: the CRC of the data type signature's 8 little-endian bytes."""
    return crc16(signature.to_bytes(8, "little"))


def transfer_crc(payload: bytes, signature: int) -> int:
    """The CRC a multi-frame transfer of a data type with ``signature`` carries in front of ``payload``."""
    return crc16(payload, signature_crc(signature))


@dataclass(frozen=True, slots=True)
class CanId:
    """A parsed 29-bit DroneCAN identifier."""

    priority: int
    service: bool
    data_type_id: int
    source: int  # 0: an anonymous message
    destination: int | None = None  # service frames only
    request: bool = False  # service frames: a request (else a response)
    discriminator: int | None = None  # anonymous message frames only

    @property
    def anonymous(self) -> bool:
        return not self.service and self.source == 0

    @property
    def protocol(self) -> str:
        return "dronecan"

    def where(self) -> str:
        """The data type and the sender, as a diagnostic names them."""
        kind = "service" if self.service else "message"
        node = f"node {self.source}" if self.source else "an anonymous node"
        return f"{kind} type {self.data_type_id} from {node}"

    @property
    def kind(self) -> str:
        if self.service:
            return "request" if self.request else "response"
        return "message"


def parse_id(can_id: int) -> CanId:
    """The fields of a 29-bit identifier (higher bits are ignored)."""
    can_id &= ID_MASK
    priority = can_id >> PRIORITY_SHIFT
    source = can_id & 0x7F
    if can_id & SERVICE_BIT:
        return CanId(
            priority,
            True,
            (can_id >> 16) & 0xFF,
            source,
            destination=(can_id >> 8) & 0x7F,
            request=bool(can_id & 0x8000),
        )
    if source == 0:
        return CanId(priority, False, (can_id >> 8) & 0x3, 0, discriminator=(can_id >> 10) & 0x3FFF)
    return CanId(priority, False, (can_id >> 8) & 0xFFFF, source)


def message_id(data_type_id: int, source: int, priority: int = 24) -> int:
    """The identifier of a message frame (used by tests and tools that build frames)."""
    return ((priority & 0x1F) << PRIORITY_SHIFT) | ((data_type_id & 0xFFFF) << 8) | (source & 0x7F)


def fd_length(length: int) -> int:
    """The smallest CAN FD data length (0..8, 12, 16, 20, 24, 32, 48, 64) that holds ``length`` bytes."""
    for size in (8, 12, 16, 20, 24, 32, 48, 64):
        if length <= size:
            return length if size == 8 else size
    return FD_DATA


def split_transfer(payload: bytes, signature: int, transfer_id: int, *, fd: bool = False) -> list[bytes]:
    """The frames' data of one transfer, tail bytes included: the inverse of reassembly, as a node sends it.

    CAN FD frames pad the payload with zero bytes to a valid data length, and the transfer CRC covers the
    padding (as pydronecan and libcanard do)."""
    room = (FD_DATA if fd else CLASSIC_DATA) - 1
    if fd and len(payload) > CLASSIC_DATA - 1:
        total = len(payload) + 1 + (2 if len(payload) + 1 > FD_DATA else 0)
        rest = total % room
        payload = payload + bytes(fd_length(rest) - rest)
    body = payload
    if len(payload) > room:
        crc = transfer_crc(payload, signature)
        body = bytes((crc & 0xFF, crc >> 8)) + payload
    frames = []
    toggle = 0
    for start in range(0, max(len(body), 1), room):
        chunk = body[start : start + room]
        tail = (TAIL_START if start == 0 else 0) | (TAIL_END if start + room >= len(body) else 0)
        frames.append(chunk + bytes((tail | toggle | (transfer_id & TRANSFER_ID_MASK),)))
        toggle ^= TAIL_TOGGLE
    return frames
