"""The frame-level facts of Cyphal/CAN (Cyphal v1 on CAN): the 29-bit identifier, the tail byte, the transfer CRC.

The identifier (Cyphal specification v1.0, section 4.2.1):

- bits 28..26 priority (0 highest .. 7); bit 25 service-not-message; bit 23 reserved, always 0; bits 6..0 the
  source node id;
- message frame: bit 24 anonymous (the source node id is then a pseudo-id); bits 22..21 reserved (sent as 1,
  ignored on reception); bits 20..8 the 13-bit subject id; bit 7 reserved, always 0;
- service frame: bit 24 request-not-response; bits 22..14 the 9-bit service id; bits 13..7 the destination node.

An identifier with a reserved bit that must be 0 set is not Cyphal (DroneCAN v0 sets them freely), so it is not
parsed. The tail byte has DroneCAN's layout -- start (bit 7), end (bit 6), toggle (bit 5), 5-bit transfer id --
but the toggle of a start frame is 1 (DroneCAN's is 0), which tells the two protocols apart on one bus. A
multi-frame transfer carries its CRC after the payload and its padding, most significant byte first:
CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF, no reflection, no final xor), not seeded by any type
signature (Cyphal has none). Only the last frame of a transfer is padded (with zero bytes, to a valid CAN FD
length), and the CRC covers the padding.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import wire

PRIORITY_SHIFT = 26
SERVICE_BIT = 1 << 25
ANONYMOUS_BIT = 1 << 24  # message frames
REQUEST_BIT = 1 << 24  # service frames
RESERVED_23 = 1 << 23
RESERVED_7 = 1 << 7  # message frames
MESSAGE_SET = 3 << 21  # message frames: reserved bits sent as 1
SUBJECT_MASK = (1 << 13) - 1
SERVICE_MASK = (1 << 9) - 1
NODE_MASK = 0x7F
START_TOGGLE = wire.TAIL_TOGGLE  # the toggle bit of a transfer's first frame


def crc16(data: bytes, initial: int = 0xFFFF) -> int:
    """CRC-16/CCITT-FALSE: the same CRC as DroneCAN's (``binascii.crc_hqx``), started from 0xFFFF."""
    return wire.crc16(data, initial)


@dataclass(frozen=True, slots=True)
class CyphalId:
    """A parsed 29-bit Cyphal/CAN identifier. ``data_type_id`` is the port id (the subject id of a message,
    the service id of a service): the field has DroneCAN's name so that both identifiers read alike."""

    priority: int
    service: bool
    data_type_id: int
    source: int  # an anonymous message's pseudo-id
    destination: int | None = None  # service frames only
    request: bool = False
    anonymous: bool = False

    @property
    def protocol(self) -> str:
        return "cyphal"

    @property
    def kind(self) -> str:
        if self.service:
            return "request" if self.request else "response"
        return "subject"

    def where(self) -> str:
        """The port and the sender, as a diagnostic names them."""
        node = f"anonymous node (pseudo-id {self.source})" if self.anonymous else f"node {self.source}"
        port = f"service {self.data_type_id}" if self.service else f"subject {self.data_type_id}"
        return f"Cyphal {port} from {node}"


def parse_id(can_id: int) -> CyphalId | None:
    """The fields of a 29-bit Cyphal/CAN identifier, or None where a reserved bit that must be clear is set
    (not a Cyphal frame: as pycyphal decides)."""
    can_id &= wire.ID_MASK
    priority = can_id >> PRIORITY_SHIFT
    source = can_id & NODE_MASK
    if can_id & RESERVED_23:
        return None
    if can_id & SERVICE_BIT:
        return CyphalId(
            priority,
            True,
            (can_id >> 14) & SERVICE_MASK,
            source,
            destination=(can_id >> 7) & NODE_MASK,
            request=bool(can_id & REQUEST_BIT),
        )
    if can_id & RESERVED_7:
        return None
    return CyphalId(priority, False, (can_id >> 8) & SUBJECT_MASK, source, anonymous=bool(can_id & ANONYMOUS_BIT))


def message_id(subject: int, source: int, priority: int = 4) -> int:
    """The identifier of a (non-anonymous) message frame, as a node sends it (reserved bits 22..21 set)."""
    return ((priority & 7) << PRIORITY_SHIFT) | MESSAGE_SET | ((subject & SUBJECT_MASK) << 8) | (source & NODE_MASK)


def split_transfer(payload: bytes, transfer_id: int, *, fd: bool = False) -> list[bytes]:
    """The frames' data of one transfer, tail bytes included, as a node sends it (the inverse of reassembly):
    the last frame padded with zeros to a valid length, the CRC after the padding in a multi-frame transfer."""
    room = (wire.FD_DATA if fd else wire.CLASSIC_DATA) - 1
    tid = transfer_id & wire.TRANSFER_ID_MASK
    if len(payload) <= room:
        padded = payload + bytes(wire.fd_length(len(payload) + 1) - len(payload) - 1) if fd else payload
        return [padded + bytes((wire.TAIL_START | wire.TAIL_END | START_TOGGLE | tid,))]
    last = (len(payload) % room) + 2  # the last frame's payload and CRC, before padding
    padding = bytes(wire.fd_length(last + 1) - last - 1) if fd and last + 1 <= wire.FD_DATA else b""
    body = payload + padding
    crc = crc16(body)
    body += bytes((crc >> 8, crc & 0xFF))
    frames = []
    toggle = START_TOGGLE
    for start in range(0, len(body), room):
        tail = (wire.TAIL_START if start == 0 else 0) | (wire.TAIL_END if start + room >= len(body) else 0)
        frames.append(body[start : start + room] + bytes((tail | toggle | tid,)))
        toggle ^= wire.TAIL_TOGGLE
    return frames
