"""MAVLink run-time support for the generated message classes: checksum, frames, stream parsing.

Standard library only. Every generated MAVLink class carries ``MSG_ID``, ``CRC_EXTRA``,
``MAVLINK_BASE_LENGTH`` and ``MAVLINK_MAX_LENGTH`` and these methods:

- ``encode(*, truncate=True) -> bytes``: the MAVLink 2 payload (wire order, trailing zero bytes
  dropped; ``truncate=False`` gives the whole ``MAVLINK_MAX_LENGTH`` record);
- ``decode(data) -> instance`` (classmethod): a payload, zero-filled when short;
- ``encode_frame(*, seq, sysid, compid, mavlink1, incompat_flags, compat_flags, signature) -> bytes``;
- ``decode_frame(data) -> instance`` (classmethod): one whole frame of that message, CRC checked;
- ``decode_batch(data, *, use_numpy=None) -> columns`` (classmethod): fixed-size records.

This module adds :func:`parse_frame` (one frame -> :class:`Frame`), :func:`decode_message` (one
frame -> an instance of whichever generated class its id names), :class:`StreamParser` (frames
out of a byte stream with garbage, with counters), :func:`scan_frames` (the fast walk over a run of
good frames that the stream parser and a .tlog reader take between damaged spots) and
:func:`message_class` (the id registry).
Text (``char[N]``) is UTF-8; bytes that are not valid UTF-8 decode through ``surrogateescape``,
so decoding never fails and encoding the text again gives back the same bytes.

The helpers the generated payload code calls live in ``_mavlink_payload``, the ids of this
package's messages in the generated ``_mavlink_registry``; both are importable from here.
"""

from __future__ import annotations

import binascii
import importlib
import struct
from collections.abc import Container
from typing import TYPE_CHECKING, Any, ClassVar, NamedTuple, Protocol

from . import _mavlink_registry
from ._mavlink_payload import (
    BytesLike,
    DecodeError,
    EncodeError,
    explain,
    fill,
    numpy_columns,
    struct_columns,
    text,
)

if TYPE_CHECKING:
    import mmap

__all__ = [
    "IFLAG_SIGNED",
    "MAGIC_V1",
    "MAGIC_V2",
    "MAX_PAYLOAD",
    "REGISTRY",
    "SIGNATURE_LENGTH",
    "BytesLike",
    "DecodeError",
    "EncodeError",
    "Frame",
    "FrameError",
    "MavlinkMessage",
    "StreamParser",
    "crc16",
    "decode_message",
    "explain",
    "fill",
    "frame_payload",
    "frame_v1",
    "frame_v2",
    "message_class",
    "numpy_columns",
    "parse_frame",
    "scan_frames",
    "struct_columns",
    "text",
]

MAGIC_V1 = 0xFE
MAGIC_V2 = 0xFD
IFLAG_SIGNED = 0x01  # the only incompatibility flag defined: a 13-byte signature follows the CRC
SIGNATURE_LENGTH = 13
MAX_PAYLOAD = 255

# msgid -> (CRC_EXTRA, class name, MAVLINK_MAX_LENGTH, MAVLink name) of every generated message
REGISTRY: dict[int, tuple[int, str, int, str]] = _mavlink_registry.REGISTRY
_MODULE = _mavlink_registry.MODULE  # the generated module holding the classes, relative to this package
_CLASSES: dict[int, type[MavlinkMessage]] = {}
_FAST: dict[int, tuple[Any, bytes, int, str]] = {}  # msgid -> (decode, CRC_EXTRA byte, size, name)

_HEAD_V2 = struct.Struct("<BBBBBBBHB")
_HEAD_V1 = struct.Struct("<BBBBBB")
_CRC = struct.Struct("<H")
# MAVLink's CRC-16/MCRF4XX is the bit-mirror of binascii's CRC-CCITT (poly 0x1021) over
# bit-mirrored bytes (init 0xFFFF is its own mirror): this runs the checksum in C.
_MIRROR = bytes(int(f"{i:08b}"[::-1], 2) for i in range(256))
_hqx = binascii.crc_hqx
_ZEROS = [bytes(i) for i in range(MAX_PAYLOAD + 1)]
_EXTRA = {msgid: bytes((entry[0],)) for msgid, entry in REGISTRY.items()}  # msgid -> CRC_EXTRA as one byte
_tuple_new = tuple.__new__  # builds a Frame without the Python-level NamedTuple.__new__ (scan_frames' hot loop)


class FrameError(DecodeError):
    """A malformed frame: bad magic, length, flags or checksum, or an unknown message id."""


class MavlinkMessage(Protocol):
    MSG_ID: ClassVar[int]
    CRC_EXTRA: ClassVar[int]

    def encode(self, *, truncate: bool = True) -> bytes: ...


def crc16(data: BytesLike, crc_extra: int | None = None) -> int:
    """CRC-16/MCRF4XX of ``data`` (then of the ``crc_extra`` byte, when given), as MAVLink sends it."""
    if crc_extra is not None:
        data = bytes(data) + bytes((crc_extra,))
    x = binascii.crc_hqx(bytes(data).translate(_MIRROR), 0xFFFF)
    return _MIRROR[x & 0xFF] << 8 | _MIRROR[x >> 8]


def message_class(msgid: int) -> type[MavlinkMessage] | None:
    """The generated class for a message id (None if this package has no such message)."""
    cls = _CLASSES.get(msgid)
    if cls is None and msgid in REGISTRY:
        module = importlib.import_module("." + _MODULE, __package__)  # lazily: it imports us
        cls = getattr(module, REGISTRY[msgid][1])
        _CLASSES[msgid] = cls
    return cls


class Frame(NamedTuple):
    """One MAVLink frame. ``version`` is 1 or 2; ``signature`` holds the 13 signature bytes of a
    signed MAVLink 2 frame (link id, 48-bit timestamp, 6-byte signature; not verified here)."""

    version: int
    msgid: int
    seq: int
    sysid: int
    compid: int
    payload: bytes
    incompat_flags: int = 0
    compat_flags: int = 0
    crc: int = 0
    signature: bytes | None = None

    @property
    def signed(self) -> bool:
        return self.signature is not None

    @property
    def link_id(self) -> int | None:
        return None if self.signature is None else self.signature[0]

    @property
    def timestamp(self) -> int | None:
        """Signature timestamp in units of 10 microseconds since 2015-01-01."""
        return None if self.signature is None else int.from_bytes(self.signature[1:7], "little")

    def message(self) -> Any:
        """The payload decoded into the generated class of ``msgid`` (FrameError if unknown)."""
        cls = message_class(self.msgid)
        if cls is None:
            raise FrameError(f"message id {self.msgid}: not a message of this package")
        return getattr(cls, "decode")(self.payload)  # noqa: B009 (MavlinkMessage does not declare decode)


def frame_v2(
    payload: bytes,
    msgid: int,
    crc_extra: bytes,
    seq: int,
    sysid: int,
    compid: int,
    incompat_flags: int = 0,
    compat_flags: int = 0,
    signature: bytes | None = None,
) -> bytes:
    """A MAVLink 2 frame around ``payload`` (``crc_extra`` as one byte); a given ``signature``
    (13 bytes, not computed here) is appended and flagged."""
    if signature is not None:
        if len(signature) != SIGNATURE_LENGTH:
            raise EncodeError(f"signature: expected {SIGNATURE_LENGTH} bytes, got {len(signature)}")
        incompat_flags |= IFLAG_SIGNED
    elif incompat_flags & IFLAG_SIGNED:
        raise EncodeError("incompat_flags: the signed flag 0x01 needs a signature")
    try:
        body = (
            _HEAD_V2.pack(
                MAGIC_V2, len(payload), incompat_flags, compat_flags, seq, sysid, compid, msgid & 0xFFFF, msgid >> 16
            )
            + payload
        )
    except struct.error as exc:
        raise EncodeError(_header_problem(seq, sysid, compid, incompat_flags, compat_flags, msgid, 24)) from exc
    x = _hqx((body[1:] + crc_extra).translate(_MIRROR), 0xFFFF)
    frame = body + bytes((_MIRROR[x >> 8], _MIRROR[x & 0xFF]))
    return frame if signature is None else frame + bytes(signature)


def frame_v1(
    payload: bytes, msgid: int, crc_extra: bytes, seq: int, sysid: int, compid: int, extras: bool = False
) -> bytes:
    """A MAVLink 1 frame around ``payload`` (message ids below 256 only; ``extras`` says flags or a
    signature were asked for, which MAVLink 1 cannot carry)."""
    if extras:
        raise EncodeError("mavlink1: MAVLink 1 frames carry no flags and no signature")
    try:
        body = _HEAD_V1.pack(MAGIC_V1, len(payload), seq, sysid, compid, msgid) + payload
    except struct.error as exc:
        raise EncodeError(_header_problem(seq, sysid, compid, 0, 0, msgid, 8)) from exc
    x = _hqx((body[1:] + crc_extra).translate(_MIRROR), 0xFFFF)
    return body + bytes((_MIRROR[x >> 8], _MIRROR[x & 0xFF]))


def _header_problem(seq: int, sysid: int, compid: int, iflags: int, cflags: int, msgid: int, id_bits: int) -> str:
    checks = (("seq", seq, 8), ("sysid", sysid, 8), ("compid", compid, 8), ("incompat_flags", iflags, 8),
              ("compat_flags", cflags, 8), ("msgid", msgid, id_bits))  # fmt: skip
    for name, value, bits in checks:
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 1 << bits:
            where = "a MAVLink 1 frame" if id_bits == 8 and name == "msgid" else f"{bits} bits"
            return f"{name}: {value!r} does not fit {where}"
    return "frame header: cannot be packed"


def _split(data: BytesLike, start: int = 0) -> tuple[Frame, int]:
    """The frame starting at data[start] and its total length (FrameError if it is not one)."""
    available = len(data) - start
    if available < 1:
        raise FrameError("frame: no bytes")
    magic = data[start]
    if magic == MAGIC_V2:
        if available < 12:
            raise FrameError(f"frame: {available} bytes are shorter than a MAVLink 2 frame (12 at least)")
        _, plen, iflags, cflags, seq, sysid, compid, low, high = _HEAD_V2.unpack_from(data, start)
        if iflags & ~IFLAG_SIGNED:
            raise FrameError(f"frame: unknown incompatibility flags 0x{iflags:02x}")
        msgid = low | high << 16
        end = start + 10 + plen
        total = 12 + plen + (SIGNATURE_LENGTH if iflags else 0)
        version = 2
    elif magic == MAGIC_V1:
        if available < 8:
            raise FrameError(f"frame: {available} bytes are shorter than a MAVLink 1 frame (8 at least)")
        _, plen, seq, sysid, compid, msgid = _HEAD_V1.unpack_from(data, start)
        iflags = cflags = 0
        end = start + 6 + plen
        total = 8 + plen
        version = 1
    else:
        raise FrameError(f"frame: expected magic 0xFD or 0xFE, got 0x{magic:02x}")
    if available < total:
        raise FrameError(f"frame: message id {msgid} needs {total} bytes, got {available}")
    entry = REGISTRY.get(msgid)
    if entry is None:
        raise FrameError(f"frame: message id {msgid} is unknown, its checksum cannot be checked")
    payload = bytes(data[end - plen : end])
    (crc,) = _CRC.unpack_from(data, end)
    expected = crc16(data[start + 1 : end], entry[0])
    if crc != expected:
        raise FrameError(
            f"frame: bad CRC for message id {msgid} ({entry[3]}): got 0x{crc:04x}, expected 0x{expected:04x}"
        )
    signature = bytes(data[end + 2 : start + total]) if iflags else None
    return Frame(version, msgid, seq, sysid, compid, payload, iflags, cflags, crc, signature), total


def parse_frame(data: BytesLike) -> Frame:
    """Exactly one MAVLink 1 or 2 frame (CRC checked with the message's CRC_EXTRA) -> Frame."""
    frame, total = _split(data)
    if total != len(data):
        raise FrameError(f"frame: {len(data) - total} bytes follow the frame")
    return frame


def scan_frames(
    data: bytes | mmap.mmap, pos: int, end: int, *, gap: int = 0, wanted: Container[int] | None = None
) -> tuple[list[Frame], list[int], int, int]:
    """The run of good frames laid back to back in ``data[pos:end]``, each after ``gap`` bytes of its own
    (8 in a .tlog: the entry's timestamp; 0 in a raw stream).

    Returns ``(frames, offsets, others, stop)``: the frames whose id is in ``wanted`` (all, when None) and
    the offsets of their entries (where their gap bytes begin), how many good frames of other ids were
    passed over, and the offset of the first entry that is not a whole frame of a message this package knows
    with good flags and a good CRC (``end`` when every one was). Such an entry is the caller's to judge
    (garbage, a cut-off frame, a bad checksum, an unknown id): :func:`parse_frame` says why. The frames
    are exactly what :func:`parse_frame` gives for the same bytes; this is its fast path for whole streams,
    a few byte reads and one checksum call per frame instead of a function call and a header struct.
    """
    frames: list[Frame] = []
    offsets: list[int] = []
    others = 0
    extras = _EXTRA
    mirror = _MIRROR
    head_v2 = _HEAD_V2.unpack_from
    while True:
        s = pos + gap
        if s + 12 <= end and data[s] == MAGIC_V2:
            _, plen, iflags, cflags, seq, sysid, compid, low, high = head_v2(data, s)
            if iflags & ~IFLAG_SIGNED:
                break
            msgid = low | high << 16
            e = s + 10 + plen  # the payload's end, where the CRC starts
            nxt = e + (2 + SIGNATURE_LENGTH if iflags else 2)
            version = 2
        elif s + 8 <= end and data[s] == MAGIC_V1:
            _, plen, seq, sysid, compid, msgid = _HEAD_V1.unpack_from(data, s)
            iflags = cflags = 0
            e = s + 6 + plen
            nxt = e + 2
            version = 1
        else:
            break
        extra = extras.get(msgid)
        # the checksum run on through the received CRC bytes leaves 0 when they match
        if nxt > end or extra is None or _hqx((data[s + 1 : e] + extra + data[e : e + 2]).translate(mirror), 0xFFFF):
            break
        if wanted is None or msgid in wanted:
            crc = data[e] | data[e + 1] << 8
            signature = data[e + 2 : nxt] if iflags else None
            frame = (version, msgid, seq, sysid, compid, data[e - plen : e], iflags, cflags, crc, signature)
            frames.append(_tuple_new(Frame, frame))
            offsets.append(pos)
        else:
            others += 1
        pos = nxt
    return frames, offsets, others, pos


def frame_payload(data: BytesLike, msgid: int, crc_extra: bytes, size: int, name: str) -> bytes:
    """The payload of one whole frame that must hold message ``msgid``, CRC checked and zero-filled
    to ``size`` bytes (the fast path of decode_frame; anything unusual goes to parse_frame)."""
    if not isinstance(data, bytes | bytearray):
        data = bytes(data)  # a memoryview has no translate()
    n = len(data)
    magic = data[0] if n else -1
    if magic == MAGIC_V2 and n >= 12:
        start = 10
        end = 10 + data[1]
        got = data[7] | data[8] << 8 | data[9] << 16
        iflags = data[2]
        tail = SIGNATURE_LENGTH if iflags == IFLAG_SIGNED else 0
    elif magic == MAGIC_V1 and n >= 8:
        start = 6
        end = 6 + data[1]
        got = data[5]
        iflags = tail = 0
    else:
        return parse_frame(data).payload  # raises the precise error
    if got != msgid:
        raise FrameError(f"{name}: frame holds message id {got}, expected {msgid}")
    # the checksum run on through the received CRC bytes leaves 0 when they match
    if (
        iflags & ~IFLAG_SIGNED
        or n != end + 2 + tail
        or _hqx((data[1:end] + crc_extra + data[end : end + 2]).translate(_MIRROR), 0xFFFF)
    ):
        parse_frame(data)  # raises the precise error
    if end - start > size:
        raise DecodeError(f"{name}: payload of {end - start} bytes exceeds the maximum length {size}")
    return bytes(data[start:end]) + _ZEROS[size - end + start]


def decode_message(data: BytesLike) -> Any:
    """One whole frame -> an instance of the generated class its message id names."""
    n = len(data)
    if n >= 12 and data[0] == MAGIC_V2:
        msgid = data[7] | data[8] << 8 | data[9] << 16
    elif n >= 8 and data[0] == MAGIC_V1:
        msgid = data[5]
    else:
        return parse_frame(data).message()
    fast = _FAST.get(msgid)
    if fast is None:
        cls = message_class(msgid)
        if cls is None:
            return parse_frame(data).message()  # raises: unknown id
        entry = REGISTRY[msgid]
        fast = _FAST[msgid] = (getattr(cls, "decode"), bytes((entry[0],)), entry[2], entry[3])  # noqa: B009
    decode, extra, size, name = fast
    return decode(frame_payload(data, msgid, extra, size, name))


class StreamParser:
    """Finds MAVLink 1/2 frames in a byte stream fed in pieces of any size.

    ``feed(data)`` returns the complete frames found so far (CRC checked with the CRC_EXTRA of the
    generated message); ``feed_messages(data)`` returns them decoded into generated instances.
    Bytes that do not start a valid frame are skipped one at a time, so the parser resynchronises
    after garbage or a corrupted frame. Counters: ``frames``, ``bad_crc``, ``unknown_msgid``
    (frames whose id this package lacks: their checksum cannot be checked, so they are skipped
    like garbage), ``bad_flags``, ``skipped_bytes``, ``decode_errors``; ``last_error`` says
    why the latest frame was rejected. With ``strict=True`` a rejected frame raises FrameError, once: the
    parser has consumed it, so feeding on resumes after it and counts no frame twice.
    """

    def __init__(self, *, strict: bool = False) -> None:
        self.strict = strict
        self._buf = bytearray()
        self._ready: list[Frame] = []  # strict mode: good frames found before a rejected one
        self._ready_messages: list[Any] = []
        self.frames = 0
        self.bad_crc = 0
        self.unknown_msgid = 0
        self.bad_flags = 0
        self.skipped_bytes = 0
        self.decode_errors = 0
        self.last_error: str | None = None

    def feed(self, data: BytesLike) -> list[Frame]:
        """The frames completed by ``data``. In strict mode a rejected frame raises FrameError once, after
        its first byte is consumed; the good frames found before it in the same call come with the next call."""
        buf = self._buf
        buf += data
        out, self._ready = self._ready, []
        view = bytes(buf)  # one copy a call: scan_frames slices bytes (payloads) out of it
        pos = 0
        n = len(view)
        while pos < n:
            run, _, _, stop = scan_frames(view, pos, n)  # the good frames from here on, in one fast walk
            if run:
                self.frames += len(run)
                out += run
                pos = stop
                continue
            # what stopped the walk (garbage, a frame cut off or rejected), judged byte by byte
            magic = view[pos]
            if magic != MAGIC_V2 and magic != MAGIC_V1:
                nxt = _next_magic(view, pos + 1)
                self.skipped_bytes += (n if nxt < 0 else nxt) - pos
                pos = n if nxt < 0 else nxt
                continue
            header = 10 if magic == MAGIC_V2 else 6
            if n - pos < header:
                break
            if magic == MAGIC_V2:
                iflags = view[pos + 2]
                total = 12 + view[pos + 1] + (SIGNATURE_LENGTH if iflags & IFLAG_SIGNED else 0)
            else:
                iflags = 0
                total = 8 + view[pos + 1]
            if iflags & ~IFLAG_SIGNED:
                self.bad_flags += 1
                self._reject(f"unknown incompatibility flags 0x{iflags:02x}", pos, out)
                pos += 1
                continue
            if n - pos < total:
                break
            try:
                frame, _ = _split(view, pos)
            except FrameError as exc:
                msgid = view[pos + 5] if magic == MAGIC_V1 else view[pos + 7] | view[pos + 8] << 8 | view[pos + 9] << 16
                if msgid in REGISTRY:
                    self.bad_crc += 1
                else:
                    self.unknown_msgid += 1
                self._reject(str(exc), pos, out)
                pos += 1
                continue
            self.frames += 1
            out.append(frame)
            pos += total
        del buf[:pos]
        return out

    def feed_messages(self, data: BytesLike) -> list[Any]:
        """Like feed(), decoded; payloads longer than the message knows count as decode_errors (strict
        mode: raise FrameError once, the messages decoded before it coming with the next call)."""
        out, self._ready_messages = self._ready_messages, []
        frames = self.feed(data)
        for i, frame in enumerate(frames):
            try:
                out.append(frame.message())
            except DecodeError as exc:
                self.decode_errors += 1
                self.last_error = str(exc)
                if self.strict:
                    self._ready = frames[i + 1 :] + self._ready
                    self._ready_messages = out
                    raise FrameError(str(exc)) from None
        return out

    @property
    def pending(self) -> int:
        """Bytes kept back, waiting for the rest of a frame."""
        return len(self._buf)

    def _reject(self, why: str, pos: int, found: list[Frame]) -> None:
        """Note why the frame at ``pos`` was rejected; in strict mode consume its first byte (and what
        came before it) and raise, keeping the frames ``found`` so far for the next call."""
        self.last_error = why
        self.skipped_bytes += 1
        if self.strict:
            del self._buf[: pos + 1]
            self._ready = found
            raise FrameError(why)


def _next_magic(buf: bytes, start: int) -> int:
    v2 = buf.find(MAGIC_V2, start)
    v1 = buf.find(MAGIC_V1, start)
    if v2 < 0:
        return v1
    return v2 if v1 < 0 else min(v1, v2)
