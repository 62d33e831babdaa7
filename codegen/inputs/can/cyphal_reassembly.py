"""Reassembling Cyphal/CAN transfers, alone or beside DroneCAN's on one bus.

:class:`CyphalReassembler` is DroneCAN's :class:`~.reassembly.Reassembler` with Cyphal/CAN's rules
(:mod:`.cyphal_wire`): the identifier (a frame whose reserved bits say it is not Cyphal is skipped, counted once),
a start frame's toggle bit set, the CRC after the payload and its padding (checked whatever the type: Cyphal has
no signature), anonymous transfers single-frame only. Its diagnostics have DroneCAN's codes and wording, the port
named as Cyphal's (``Cyphal subject 4096 from node 12``).

:class:`MixedReassembler` reads a bus that carries both (a vehicle moving from DroneCAN to Cyphal, or a
capture of two buses): a start frame with its toggle bit set and an identifier that can be Cyphal's is
Cyphal's, any other start frame DroneCAN's; a later frame belongs to the protocol with a transfer in progress on
its identifier (Cyphal's first), else it is DroneCAN's stray frame. A DroneCAN start frame whose toggle bit is
damaged is therefore read as a Cyphal transfer (its CRC, or its port's type, then fails): the one case two
protocols sharing a tail byte cannot tell apart.
"""

from __future__ import annotations

from collections.abc import Sequence

from . import cyphal_wire, wire
from .reassembly import TIMEOUT, Diagnostic, Event, Frame, Reassembler, Signatures, _Pending


class CyphalReassembler(Reassembler):
    """Frames in, Cyphal/CAN transfers (their payload with any padding, the CRC removed) and diagnostics out."""

    NAME = "Cyphal/CAN"
    START_TOGGLE = cyphal_wire.START_TOGGLE
    KEY_MASK = wire.ID_MASK >> 3  # the identifier less its 3 priority bits: one transfer in progress per session

    def __init__(self, *, timeout: float = TIMEOUT, name: str | None = None) -> None:
        super().__init__({}, timeout=timeout, name=name)

    def _parse_id(self, can_id: int) -> cyphal_wire.CyphalId:
        parsed = cyphal_wire.parse_id(can_id)
        assert parsed is not None  # _foreign turned the others away
        return parsed

    def _foreign(self, can_id: int) -> bool:
        return cyphal_wire.parse_id(can_id) is None

    def in_progress(self, can_id: int) -> bool:
        """Whether a transfer is being received on this identifier's session."""
        return (can_id & self.KEY_MASK) in self._pending

    def _refused(self, id_: wire.CanId | cyphal_wire.CyphalId, frame: Frame, tail: int) -> Diagnostic | None:
        if id_.anonymous and not tail & wire.TAIL_END:
            # the specification allows anonymous transfers one frame only: a node without an id cannot be
            # told apart from another one sending on the same subject
            text = f"{id_.where()}: a multi-frame anonymous transfer {tail & wire.TRANSFER_ID_MASK}; dropped"
            return Diagnostic("can-anonymous", text, frame.t, frame.index, id_.source, id_.data_type_id)
        return None

    def _multi_frame(self, p: _Pending, body: bytes, out: list[Event]) -> tuple[bytes, bool] | None:
        if len(body) < 2:
            out.append(self._crc_problem(p, f"transfer {p.transfer_id} too short for its CRC"))
            return None
        carried = (body[-2] << 8) | body[-1]
        computed = cyphal_wire.crc16(body[:-2])
        if computed != carried:
            text = f"transfer {p.transfer_id} CRC 0x{carried:04X}, expected 0x{computed:04X}; dropped"
            out.append(self._crc_problem(p, text))
            return None
        return body[:-2], True


class MixedReassembler:
    """DroneCAN and Cyphal/CAN transfers of one bus, each frame handed to the protocol it belongs to."""

    def __init__(self, signatures: Signatures, *, timeout: float = TIMEOUT) -> None:
        self.dronecan = Reassembler(signatures, timeout=timeout, name="DroneCAN or Cyphal/CAN")
        self.cyphal = CyphalReassembler(timeout=timeout)

    @property
    def frames(self) -> int:
        return self.dronecan.frames + self.cyphal.frames

    @property
    def transfers(self) -> int:
        return self.dronecan.transfers + self.cyphal.transfers

    def feed(self, frame: Frame) -> Sequence[Event]:
        return self._owner(frame).feed(frame)

    def _owner(self, frame: Frame) -> Reassembler:
        if frame.kind != "data" or not frame.extended or not frame.data:
            return self.dronecan  # error, remote, 11-bit and empty frames: reported once, by one of them
        tail = frame.data[-1]
        if tail & wire.TAIL_START:
            cyphal = tail & wire.TAIL_TOGGLE and cyphal_wire.parse_id(frame.can_id) is not None
            return self.cyphal if cyphal else self.dronecan
        return self.cyphal if self.cyphal.in_progress(frame.can_id) else self.dronecan

    def finish(self, t: float, index: int) -> list[Diagnostic]:
        return self.dronecan.finish(t, index) + self.cyphal.finish(t, index)


TRANSPORTS = ("dronecan", "cyphal", "mixed")


def reassembler_for(transport: str, signatures: Signatures) -> Reassembler | MixedReassembler:
    """The reassembler of a bus carrying ``transport``: ``dronecan``, ``cyphal`` or ``mixed`` (both)."""
    if transport == "cyphal":
        return CyphalReassembler()
    if transport == "mixed":
        return MixedReassembler(signatures)
    return Reassembler(signatures)


def cyphal_hint(reassembler: Reassembler | MixedReassembler, t: float, index: int) -> Diagnostic | None:
    """Where a bus read as DroneCAN only had start frames with their toggle bit set as Cyphal/CAN's are: a
    ``can-cyphal-like`` note saying how to read it as Cyphal (None otherwise)."""
    if type(reassembler) is not Reassembler or not reassembler.cyphal_like:
        return None
    text = (
        f"{reassembler.cyphal_like} start frame(s) had their toggle bit set, as Cyphal/CAN's start frames do: if "
        "this bus carries Cyphal, read it as such (--transport cyphal or mixed, --cyphal-subject ID=TYPE)"
    )
    return Diagnostic("can-cyphal-like", text, t, index, severity="warning")
