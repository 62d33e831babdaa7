"""Reassembling DroneCAN transfers from a stream of CAN frames, with transport diagnostics.

A :class:`Reassembler` is fed frames in capture order and hands out completed :class:`Transfer`\\ s and
:class:`Diagnostic`\\ s: the transport errors a bus debugger looks for (a wrong toggle bit, a transfer CRC that
does not match the data type's signature, a continuation frame without its start, a transfer that never ends or
is restarted, skipped transfer ids). It keeps one transfer in progress per identifier (less the priority bits),
bounded in number and length, so its memory stays flat however long the capture.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from . import cyphal_wire, wire

TIMEOUT = 2.0  # seconds a transfer may take between frames (libcanard's and pydronecan's receive timeout)
MAX_PAYLOAD = 4096  # bytes: far above any DroneCAN v0 data type; a longer transfer is damage
MAX_PENDING = 1024  # transfers in progress at once; the oldest is dropped past this


@dataclass(frozen=True, slots=True)
class Frame:
    """One CAN frame of a capture: where it is (0-based ``index``, ``t`` in seconds), its identifier and data."""

    index: int
    t: float
    can_id: int
    data: bytes
    extended: bool = True
    fd: bool = False
    channel: str = ""
    kind: str = "data"  # "error" or "remote": not DroneCAN, but a bus that carries them is worth a word


@dataclass(frozen=True, slots=True)
class Transfer:
    """A completed transfer: its identifier, transfer id, payload (the CRC removed) and where it was."""

    t: float  # time of its first frame
    frame: int  # index of its first frame
    last_frame: int
    id: wire.CanId | cyphal_wire.CyphalId
    transfer_id: int
    payload: bytes
    frames: int
    fd: bool = False
    crc_checked: bool = True  # False: a multi-frame transfer of a data type whose signature is unknown

    @property
    def node(self) -> int:
        return self.id.source


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """A transport problem (or, with severity ``info``, a fact) found at one frame of a capture."""

    code: str  # a stable name: can-toggle, can-crc, can-missing-start, ...
    message: str
    t: float
    frame: int
    node: int | None = None
    data_type_id: int | None = None
    severity: str = "error"

    def to_dict(self) -> dict[str, object]:
        return {
            "code": self.code,
            "severity": self.severity,
            "t": self.t,
            "frame": self.frame,
            "node": self.node,
            "data_type_id": self.data_type_id,
            "message": self.message,
        }


@dataclass(slots=True)
class _Pending:
    first: Frame
    id: wire.CanId | cyphal_wire.CyphalId
    transfer_id: int
    last_t: float
    toggle: int = 0
    count: int = 0
    fd: bool = False
    chunks: list[bytes] = field(default_factory=list)
    size: int = 0


Event = Transfer | Diagnostic
_NOTHING: tuple[Event, ...] = ()
_KEY_MASK = wire.ID_MASK >> 5  # the identifier less its 5 priority bits: one transfer in progress per key
Signatures = Mapping[tuple[str, int], int]  # ("message" | "service", data type id) -> signature


def _where(id_: wire.CanId | cyphal_wire.CyphalId) -> str:
    return id_.where()


class Reassembler:
    """Frames in, transfers and diagnostics out. ``signatures`` gives the data type signature of each known
    (``"message"``/``"service"``, id) for the transfer CRC; a multi-frame transfer of another type is handed
    out with ``crc_checked=False`` and one ``can-unknown-type`` notice per type. ``name``: the protocol(s) a
    skipped frame is said not to be.

    DroneCAN's; :class:`.cyphal_reassembly.CyphalReassembler` overrides what Cyphal/CAN does otherwise (the
    identifier, the start frame's toggle, where the CRC is and what seeds it)."""

    NAME = "DroneCAN"
    START_TOGGLE = 0  # the toggle bit of a transfer's first frame
    KEY_MASK = _KEY_MASK

    def __init__(self, signatures: Signatures, *, timeout: float = TIMEOUT, name: str | None = None) -> None:
        self.name = name or self.NAME
        self._signatures = signatures
        self._seeds: dict[int, int] = {}  # signature -> its CRC seed, computed once
        self._timeout = timeout
        self._pending: dict[int, _Pending] = {}
        self._last_tid: dict[tuple[int, bool, int], int] = {}
        self._unknown: set[tuple[bool, int]] = set()
        self._skipped: dict[str, int] = {}
        self.cyphal_like = 0  # DroneCAN start frames refused for a toggle bit set as Cyphal/CAN's start frames have it
        self.frames = 0
        self.transfers = 0

    def feed(self, frame: Frame) -> Sequence[Event]:
        """The transfers completed and the problems found by one more frame (usually none: an empty tuple)."""
        self.frames += 1
        out: list[Event] = []
        if not self.frames & 63 and self._pending:  # now and then, transfers whose sender went quiet
            out.extend(self._expire(frame.t, frame.index))
        if frame.kind != "data":
            out.append(self._signal(frame))
            return out
        data = frame.data
        if not frame.extended or not data or self._foreign(frame.can_id):
            out.extend(self._not_dronecan(frame))
            return out
        tail = data[-1]
        key = frame.can_id & self.KEY_MASK
        pending = self._pending.get(key)
        if pending is not None and frame.t - pending.last_t > self._timeout:
            out.append(self._lost(pending, "timed out", frame))
            del self._pending[key]
            pending = None
        if tail & wire.TAIL_START:
            if pending is not None:
                out.append(self._lost(pending, "restarted by a new start frame", frame))
                del self._pending[key]
            pending = self._start(key, frame, tail, out)
            if pending is None:
                return out
        elif pending is None or (tail & wire.TRANSFER_ID_MASK) != pending.transfer_id:
            out.append(self._stray(frame, tail, pending))
            if pending is not None:
                del self._pending[key]
            return out
        elif tail & wire.TAIL_TOGGLE != pending.toggle:
            out.append(self._bad_toggle(frame, tail, pending))
            del self._pending[key]
            return out
        else:
            pending.chunks.append(data[:-1])
            pending.size += len(data) - 1
            pending.count += 1
            pending.toggle ^= wire.TAIL_TOGGLE
            pending.last_t = frame.t
            pending.fd = pending.fd or frame.fd
            if pending.size > MAX_PAYLOAD:
                out.append(self._too_long(frame, pending))
                del self._pending[key]
                return out
        if tail & wire.TAIL_END:
            self._pending.pop(key, None)
            out.extend(self._complete(pending, frame))
        return out if out else _NOTHING

    def _parse_id(self, can_id: int) -> wire.CanId | cyphal_wire.CyphalId:
        return wire.parse_id(can_id)

    def _foreign(self, can_id: int) -> bool:
        """Whether an extended identifier cannot be this protocol's (every one can be DroneCAN's)."""
        return False

    def _refused(self, id_: wire.CanId | cyphal_wire.CyphalId, frame: Frame, tail: int) -> Diagnostic | None:
        """A start frame the protocol forbids whatever its toggle bit (none in DroneCAN)."""
        return None

    def _start(self, key: int, frame: Frame, tail: int, out: list[Event]) -> _Pending | None:
        """A transfer's first frame: its state (kept in progress unless it also ends here), or None if refused."""
        id_ = self._parse_id(frame.can_id)
        tid = tail & wire.TRANSFER_ID_MASK
        refused = self._refused(id_, frame, tail)
        if refused is not None:
            out.append(refused)
            return None
        if tail & wire.TAIL_TOGGLE != self.START_TOGGLE:
            if not self.START_TOGGLE and cyphal_wire.parse_id(frame.can_id) is not None:
                self.cyphal_like += 1
            found, expected = ("clear", "set") if self.START_TOGGLE else ("set", "clear")
            text = (
                f"{_where(id_)}: toggle bit {found} on the start frame of transfer {tid} (expected {expected}); dropped"
            )
            out.append(Diagnostic("can-toggle", text, frame.t, frame.index, id_.source, id_.data_type_id))
            return None
        toggle = self.START_TOGGLE ^ wire.TAIL_TOGGLE  # the next frame's
        pending = _Pending(frame, id_, tid, frame.t, toggle, 1, frame.fd, [frame.data[:-1]], len(frame.data) - 1)
        if not tail & wire.TAIL_END:
            if len(self._pending) >= MAX_PENDING:
                oldest = min(self._pending, key=lambda k: self._pending[k].last_t)
                out.append(self._lost(self._pending.pop(oldest), "dropped: too many transfers in progress", frame))
            self._pending[key] = pending
        return pending

    def _signal(self, frame: Frame) -> Diagnostic:
        # an error frame is the controller reporting bus damage (each frame counted, as a warning: no transfer
        # is lost by it alone); a remote frame asks for data, which DroneCAN never does
        what = "a bus error frame" if frame.kind == "error" else f"a remote (RTR) frame: not {self.name}, skipped"
        return Diagnostic(f"can-{frame.kind}-frame", what, frame.t, frame.index, severity="warning")

    def _not_dronecan(self, frame: Frame) -> list[Diagnostic]:
        if frame.data:
            # an 11-bit frame, or a 29-bit one with an identifier this protocol cannot have: said once each
            code, what = ("can-foreign-id", "a 29-bit") if frame.extended else ("can-standard-id", "an 11-bit")
            self._skipped[code] = seen = self._skipped.get(code, 0) + 1
            if seen > 1:
                return []
            text = f"{what} frame: not {self.name}, skipped (counted once)"
            return [Diagnostic(code, text, frame.t, frame.index, severity="info")]
        return [Diagnostic("can-empty-frame", "a frame without data: no tail byte", frame.t, frame.index)]

    def _stray(self, frame: Frame, tail: int, pending: _Pending | None) -> Diagnostic:
        id_ = self._parse_id(frame.can_id)
        tid = tail & wire.TRANSFER_ID_MASK
        if pending is None:
            text = f"{_where(id_)}: a frame of transfer {tid} without its start frame"
            return Diagnostic("can-missing-start", text, frame.t, frame.index, id_.source, id_.data_type_id)
        text = f"{_where(id_)}: transfer id {tid} inside transfer {pending.transfer_id}; both dropped"
        return Diagnostic("can-transfer-id", text, frame.t, frame.index, id_.source, id_.data_type_id)

    def _bad_toggle(self, frame: Frame, tail: int, pending: _Pending) -> Diagnostic:
        id_ = pending.id
        text = (
            f"{_where(id_)}: toggle bit {(tail & wire.TAIL_TOGGLE) >> 5} on frame {pending.count + 1} of transfer "
            f"{pending.transfer_id} (expected {pending.toggle >> 5}); transfer dropped"
        )
        return Diagnostic("can-toggle", text, frame.t, frame.index, id_.source, id_.data_type_id)

    def _too_long(self, frame: Frame, pending: _Pending) -> Diagnostic:
        id_ = pending.id
        text = f"{_where(id_)}: transfer {pending.transfer_id} longer than {MAX_PAYLOAD} bytes; dropped"
        return Diagnostic("can-too-long", text, frame.t, frame.index, id_.source, id_.data_type_id)

    def finish(self, t: float, index: int) -> list[Diagnostic]:
        """The transfers still in progress at the end of the capture, as ``can-missing-end`` problems."""
        lost = [self._lost(p, "not finished when the capture ended", None, t, index) for p in self._pending.values()]
        self._pending.clear()
        return lost

    def _expire(self, t: float, index: int) -> list[Diagnostic]:
        stale = [k for k, p in self._pending.items() if t - p.last_t > self._timeout]
        return [self._lost(self._pending.pop(k), "timed out", None, t, index) for k in stale]

    def _lost(self, p: _Pending, why: str, frame: Frame | None, t: float = 0.0, index: int = 0) -> Diagnostic:
        at_t, at = (frame.t, frame.index) if frame is not None else (t, index)
        return Diagnostic(
            "can-missing-end",
            f"{_where(p.id)}: transfer {p.transfer_id} (started at frame {p.first.index}, {p.count} frame(s)) {why}",
            at_t,
            at,
            p.id.source,
            p.id.data_type_id,
        )

    def _complete(self, p: _Pending, last: Frame) -> list[Event]:
        out: list[Event] = []
        body = p.chunks[0] if p.count == 1 else b"".join(p.chunks)
        checked = True
        if p.count > 1:
            crc_checked = self._multi_frame(p, body, out)
            if crc_checked is None:
                return out
            body, checked = crc_checked
        if not p.id.service and not p.id.anonymous:
            out.extend(self._gap(p))
        self.transfers += 1
        out.append(Transfer(p.first.t, p.first.index, last.index, p.id, p.transfer_id, body, p.count, p.fd, checked))
        return out

    def _multi_frame(self, p: _Pending, body: bytes, out: list[Event]) -> tuple[bytes, bool] | None:
        """A multi-frame transfer's payload without its CRC, and whether the CRC was checked; None (and the
        problem in ``out``) where the CRC does not match."""
        if len(body) < 2:
            out.append(self._crc_problem(p, f"transfer {p.transfer_id} too short for its CRC"))
            return None
        kind = "service" if p.id.service else "message"
        signature = self._signatures.get((kind, p.id.data_type_id))
        carried, body = body[0] | (body[1] << 8), body[2:]
        if signature is None:
            if (p.id.service, p.id.data_type_id) not in self._unknown:
                self._unknown.add((p.id.service, p.id.data_type_id))
                text = "data type not known, so its transfer CRC is not checked (reported once per type)"
                out.append(self._crc_problem(p, text, "can-unknown-type", "info"))
            return body, False
        seed = self._seeds.get(signature)
        if seed is None:
            seed = self._seeds[signature] = wire.signature_crc(signature)
        computed = wire.crc16(body, seed)
        if computed != carried:
            text = (
                f"transfer {p.transfer_id} CRC 0x{carried:04X}, "
                f"expected 0x{computed:04X} for signature 0x{signature:016X}; dropped"
            )
            out.append(self._crc_problem(p, text))
            return None
        return body, True

    def _crc_problem(self, p: _Pending, text: str, code: str = "can-crc", severity: str = "error") -> Diagnostic:
        return Diagnostic(
            code, f"{_where(p.id)}: {text}", p.first.t, p.first.index, p.id.source, p.id.data_type_id, severity
        )

    def _gap(self, p: _Pending) -> list[Diagnostic]:
        key = (p.id.source, p.id.service, p.id.data_type_id)
        last = self._last_tid.get(key)
        self._last_tid[key] = p.transfer_id
        if last is None:
            return []
        missed = (p.transfer_id - last - 1) % wire.TRANSFER_IDS
        if missed == 0 or missed == wire.TRANSFER_IDS - 1:  # the next one, or a repeat (redundant interfaces)
            return []
        return [
            Diagnostic(
                "can-tid-gap",
                f"{_where(p.id)}: transfer id {p.transfer_id} after {last}: {missed} transfer(s) missing",
                p.first.t,
                p.first.index,
                p.id.source,
                p.id.data_type_id,
                severity="warning",
            )
        ]
