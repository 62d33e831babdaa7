"""MAVLink logs as records: telemetry logs (.tlog) and raw MAVLink byte streams (.mav).

A .tlog (MAVProxy, QGroundControl, Mission Planner) is a sequence of entries, each a big-endian
uint64 time in microseconds (Unix epoch) followed by one MAVLink 1 or 2 frame. Entries are walked
by their frames' lengths. A frame of a message the generated package knows (the wanted one among them)
counts only with a good checksum (its CRC_EXTRA); a frame of another message cannot be checked and is
skipped when it is plausible (it ends where the next entry's frame begins, or at the end of the file)
and no frame with a good checksum starts inside it, so a stray magic byte cannot swallow a real frame.
Bytes that do not start an entry are garbage: reading resumes at the next magic byte that starts an entry.
The file is memory-mapped, so memory stays flat whatever its size.

A raw stream (``.mav`` or ``--input-format mavlink``; not ``.bin``, which is ArduPilot's DataFlash
log) is fed in 64 KiB pieces to the generated :class:`StreamParser`, which resynchronises after
garbage; its counters become the damage summary. Raw streams carry no times and the parser no
offsets: such records are located by frame number, system/component id and sequence number.

Damage (bad CRCs, garbage, a cut-off last frame) is one warning notice per file, never a failure;
a non-empty file in which no frame at all is found is unreadable.
"""

from __future__ import annotations

import mmap
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, NamedTuple

from ..errors import cannot_read
from .model import Frame, GeneratedMessage, MavlinkClass, MavlinkRuntime, mavlink_runtime
from .records import InputError, Item, Notice, Record

Buffer = bytes | mmap.mmap  # a whole .tlog: the file mapped, or the bytes of a stream

CHUNK = 1 << 16
MAGIC_V1, MAGIC_V2 = 0xFE, 0xFD
SIGNED = 0x01
_STAMP = 8
_tuple_new = tuple.__new__  # a FrameRecord without the Python-level NamedTuple.__new__ (the walk's hot loop)
_RUN = 1 << 12  # bytes walked per fast run: the frames of one run are held in a list, so memory stays flat


@dataclass
class StreamStats:
    """What a MAVLink log held besides the wanted records."""

    records: int = 0  # frames of the wanted message, decoded
    other_frames: int = 0  # frames of other messages (tlog: exact; raw: as the parser counts them)
    bad_crc: int = 0
    garbage_bytes: int = 0
    decode_errors: int = 0  # frames of the wanted message whose payload is too long
    truncated_bytes: int = 0  # an entry or frame cut off at the end of the file
    problems: list[str] = field(default_factory=list)
    first_stamp: int | None = None  # tlog: the stamp of the log's first frame (any message), µs since the epoch

    def seen(self, stamp: int) -> None:
        """A frame of any message with this tlog stamp was read (the first one is the log's start)."""
        if self.first_stamp is None and stamp < 1 << 63:  # a stamp past int64 is a damaged one: unknown
            self.first_stamp = stamp

    @property
    def damaged(self) -> bool:
        return bool(self.bad_crc or self.garbage_bytes or self.decode_errors or self.truncated_bytes)

    def to_dict(self) -> dict[str, object]:
        return {
            "records": self.records,
            "other_frames": self.other_frames,
            "bad_crc": self.bad_crc,
            "garbage_bytes": self.garbage_bytes,
            "decode_errors": self.decode_errors,
            "truncated_bytes": self.truncated_bytes,
        }

    def summary(self, what: str) -> str:
        parts = [f"{self.records} {what} records", f"{self.other_frames} frames of other messages skipped"]
        if self.bad_crc:
            parts.append(f"{self.bad_crc} {what} frames with a bad CRC skipped")
        if self.decode_errors:
            parts.append(f"{self.decode_errors} {what} frames too long to decode skipped")
        if self.garbage_bytes:
            parts.append(f"{self.garbage_bytes} bytes of garbage skipped")
        if self.truncated_bytes:
            parts.append(f"{self.truncated_bytes} bytes cut off at the end of the file")
        return ", ".join(parts)


class FrameRecord(NamedTuple):
    """One decoded frame of the wanted message and where it was (a NamedTuple, built with ``tuple.__new__``
    in the walk's hot loop: a frozen dataclass's ``__init__`` cost a third of a frame's checksum)."""

    number: int  # 0-based among the wanted message's frames
    offset: int | None  # of the tlog entry (its timestamp); None in a raw stream
    timestamp: int | None  # tlog time, microseconds since the Unix epoch
    frame: Frame
    instance: GeneratedMessage

    def where(self, name: str) -> str:
        f = self.frame
        head = f"{name} #{self.number} from {f.sysid}/{f.compid} seq {f.seq}"
        stamp = f" at {self.timestamp} us" if self.timestamp is not None else ""
        place = f", offset {self.offset}" if self.offset is not None else ""
        return head + stamp + place

    def location(self) -> dict[str, object]:
        f = self.frame
        out: dict[str, object] = {"frame": self.number, "sysid": f.sysid, "compid": f.compid, "seq": f.seq}
        if self.timestamp is not None:
            out["timestamp_us"] = self.timestamp
        if self.offset is not None:
            out["offset"] = self.offset
        return out


def _frame_length(data: Buffer, start: int, end: int) -> tuple[int, int] | None:
    """(total length, message id) of the frame whose header starts at ``start``, if it is whole."""
    magic = data[start]
    if magic == MAGIC_V2:
        if end - start < 10:
            return None
        return 12 + data[start + 1] + (13 if data[start + 2] & SIGNED else 0), data[start + 7] | data[
            start + 8
        ] << 8 | data[start + 9] << 16
    if end - start < 6:
        return None
    return 8 + data[start + 1], data[start + 5]


_MAGIC_BYTES = (bytes([MAGIC_V1]), bytes([MAGIC_V2]))


def _is_magic(byte: int) -> bool:
    return byte == MAGIC_V1 or byte == MAGIC_V2


def tlog_frames(data: Buffer, model: MavlinkClass, stats: StreamStats) -> Iterator[FrameRecord]:
    """The frames of ``model``'s message in a .tlog held in ``data`` (bytes or an mmap)."""
    return tlog_messages(data, {model.MSG_ID: model}, stats)


def tlog_messages(data: Buffer, models: Mapping[int, MavlinkClass], stats: StreamStats) -> Iterator[FrameRecord]:
    """The frames of every wanted message (``models`` by message id) in a .tlog held in ``data``, in file
    order, in one walk; ``FrameRecord.number`` counts among the frames of the record's own message."""
    if not models:
        return
    rt = mavlink_runtime(next(iter(models.values())))
    numbers = dict.fromkeys(models, 0)
    decoders = {msgid: model.decode for msgid, model in models.items()}
    end = len(data)
    pos = released = 0
    while pos < end:
        if pos - released >= _RELEASE:
            released = _release(data, released, pos)
        start = pos + _STAMP
        if start >= end:
            stats.truncated_bytes += end - pos
            return
        if _is_magic(data[start]):
            head = _frame_length(data, start, end)
            if head is None or start + head[0] > end:
                if head is None or _first_verified(data, rt, start + 1, end) < 0:
                    stats.truncated_bytes += end - pos
                    return
                pos = _resync(data, pos, end, stats)  # a stray magic byte claiming more than is left
                continue
            total, got = head
            if got in rt.REGISTRY and stats.first_stamp is not None:  # (until then every stamp goes to seen())
                # a known message's frame: the runtime's fast walk checks it and the run of good frames of
                # known messages after it; what stops the run (damage, another message) is judged below
                run, offsets, others, stop = rt.scan_frames(data, pos, min(end, pos + _RUN), gap=_STAMP, wanted=models)
                if stop > pos:
                    stats.other_frames += others
                    for frame, offset in zip(run, offsets, strict=True):
                        got = frame.msgid
                        try:
                            obj = decoders[got](frame.payload)
                        except ValueError as exc:  # DecodeError: a payload longer than the message
                            stats.decode_errors += 1
                            stats.problems.append(str(exc))
                            continue
                        stats.records += 1
                        number = numbers[got]
                        numbers[got] = number + 1
                        stamp = int.from_bytes(data[offset : offset + _STAMP], "big")
                        yield _tuple_new(FrameRecord, (number, offset, stamp, frame, obj))
                    pos = stop
                    continue
            after = start + total
            plausible = after == end or (after + _STAMP < end and _is_magic(data[after + _STAMP]))
            if got in rt.REGISTRY:  # its CRC_EXTRA is known: only a frame with a good CRC counts
                try:
                    frame = rt.parse_frame(data[start:after])
                except ValueError as exc:  # FrameError: bad CRC, flags
                    # a damaged frame of a wanted message, unless a good frame starts inside it
                    if got in models and plausible and _first_verified(data, rt, start + 1, after + _STAMP) < 0:
                        stats.bad_crc += 1
                        stats.problems.append(f"offset {pos}: {exc}")
                        pos = after
                        continue
                else:
                    stamp = int.from_bytes(data[pos:start], "big")
                    stats.seen(stamp)
                    model = models.get(got)
                    if model is not None:
                        record = _decode(frame, model, stats, pos, stamp, numbers[got])
                        if record is not None:
                            numbers[got] += 1
                            yield record
                    else:
                        stats.other_frames += 1
                    pos = after
                    continue
            elif plausible and _first_verified(data, rt, start + 1, after + _STAMP) < 0:
                # another message (no CRC_EXTRA to check it with), trusted as far as no frame with a
                # good checksum starts inside it: a stray magic byte must not swallow a real frame
                stats.seen(int.from_bytes(data[pos:start], "big"))
                stats.other_frames += 1
                pos = after
                continue
        pos = _resync(data, pos, end, stats)


_RELEASE = 8 << 20  # bytes of a mapped tlog walked past before their pages are let go


def _release(data: Buffer, lo: int, hi: int) -> int:
    """Let this process's pages of ``data[lo:hi]`` go (the walk never looks back, and a decoded frame holds a
    copy of its bytes): a map's pages count in the resident size once read, so a whole tlog walked would be,
    each walk, the file's size on top of the export's memory; the kernel reads them again should anything touch
    them. Returns the new start of what is kept (``lo`` stays page-aligned)."""
    hi -= hi % mmap.PAGESIZE
    if isinstance(data, mmap.mmap) and hasattr(mmap, "MADV_DONTNEED") and hi > lo:
        data.madvise(mmap.MADV_DONTNEED, lo, hi - lo)
    return max(lo, hi)


def _first_verified(data: Buffer, rt: MavlinkRuntime, lo: int, hi: int) -> int:
    """The first position in [lo, hi) where a frame of a message this package knows starts with a good
    CRC (-1: none); only magic bytes followed by a known id are checked, so this stays cheap."""
    end = len(data)
    hi = min(hi, end)
    while lo < hi:
        v2 = data.find(b"\xfd", lo, hi)
        v1 = data.find(b"\xfe", lo, hi)
        m = v1 if v2 < 0 else v2 if v1 < 0 else min(v1, v2)
        if m < 0:
            return -1
        head = _frame_length(data, m, end)
        if head is not None and head[1] in rt.REGISTRY and m + head[0] <= end:
            try:
                rt.parse_frame(data[m : m + head[0]])
            except ValueError:
                pass
            else:
                return m
        lo = m + 1
    return -1


_RESYNC_WINDOW = 1 << 16  # bytes searched for a magic at once: a stretch of garbage costs C speed, not a loop


def _resync(data: Buffer, pos: int, end: int, stats: StreamStats) -> int:
    """The next entry start after garbage at ``pos`` (``end`` when there is none): the first byte that could be a
    frame's magic, found by ``find`` a window at a time (a byte-by-byte loop took minutes on a few hundred MB of
    garbage, such as a tlog whose tail is zeros)."""
    lo = pos + 1 + _STAMP
    while lo < end:
        hi = min(end, lo + _RESYNC_WINDOW)
        hits = [i for i in (data.find(_MAGIC_BYTES[0], lo, hi), data.find(_MAGIC_BYTES[1], lo, hi)) if i >= 0]
        if hits:
            cand = min(hits) - _STAMP
            stats.garbage_bytes += cand - pos
            return cand
        lo = hi
    stats.garbage_bytes += end - pos
    return end


def _decode(
    frame: Frame, model: MavlinkClass, stats: StreamStats, offset: int | None, stamp: int | None, number: int = -1
) -> FrameRecord | None:
    try:
        obj = model.decode(frame.payload)
    except ValueError as exc:  # DecodeError: a payload longer than the message
        stats.decode_errors += 1
        stats.problems.append(str(exc))
        return None
    stats.records += 1
    return FrameRecord(stats.records - 1 if number < 0 else number, offset, stamp, frame, obj)


def raw_frames(stream: IO[bytes], model: MavlinkClass, stats: StreamStats) -> Iterator[FrameRecord]:
    """The frames of ``model``'s message in a raw MAVLink byte stream, read in CHUNK pieces."""
    rt = mavlink_runtime(model)
    msgid = model.MSG_ID
    parser = rt.StreamParser()
    seen = 0
    while True:
        chunk = stream.read(CHUNK)
        if not chunk:
            break
        seen += len(chunk)
        for frame in parser.feed(chunk):
            if frame.msgid != msgid:
                stats.other_frames += 1
                continue
            record = _decode(frame, model, stats, None, None)
            if record is not None:
                yield record
    stats.bad_crc = parser.bad_crc
    stats.other_frames += parser.unknown_msgid  # ids this package lacks (their checksums cannot be checked)
    stats.garbage_bytes = parser.skipped_bytes
    stats.truncated_bytes = parser.pending
    if parser.last_error:
        stats.problems.append(parser.last_error)
    if seen and not (parser.frames or parser.unknown_msgid or parser.bad_crc):
        raise InputError("", 0, f"expected a MAVLink byte stream: no frame in {seen} bytes")


def _open_map(path: Path, name: str) -> mmap.mmap | bytes:
    try:
        with path.open("rb") as f:
            if f.seek(0, 2) == 0:
                return b""
            return mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
    except OSError as exc:
        raise InputError(name, 0, cannot_read(exc)) from None


def read_frames(
    path: Path | IO[bytes], name: str, model: MavlinkClass, stats: StreamStats, *, timestamps: bool
) -> Iterator[FrameRecord]:
    """The wanted frames of a .tlog (``timestamps``) or raw stream, from a path or a binary stream.
    Raises InputError (naming ``name``) when nothing in a non-empty input is MAVLink."""
    if not timestamps:
        if isinstance(path, Path):
            try:
                stream: IO[bytes] = path.open("rb")
            except OSError as exc:
                raise InputError(name, 0, cannot_read(exc)) from None
        else:
            stream = path
        try:
            yield from raw_frames(stream, model, stats)
        except InputError as exc:
            raise InputError(name, 0, exc.message) from None
        finally:
            if isinstance(path, Path):
                stream.close()
        return
    data = _open_map(path, name) if isinstance(path, Path) else path.read()
    size = len(data)
    try:
        yield from tlog_frames(data, model, stats)
    finally:
        if isinstance(data, mmap.mmap):
            data.close()
    if size and not (stats.records or stats.other_frames or stats.bad_crc or stats.decode_errors):
        raise InputError(
            name, 0, "expected a MAVLink telemetry log: no 8-byte timestamp followed by a MAVLink frame found"
        )


def read_messages(
    path: Path, name: str, models: Mapping[int, MavlinkClass], stats: StreamStats
) -> Iterator[FrameRecord]:
    """The frames of every wanted message of a .tlog file, in file order, from one CRC-checked walk (see the
    module's docs); an InputError (naming ``name``) when nothing in a non-empty file is MAVLink."""
    data = _open_map(path, name)
    size = len(data)
    try:
        yield from tlog_messages(data, models, stats)
    finally:
        if isinstance(data, mmap.mmap):
            data.close()
    if size and stats.first_stamp is None and not (stats.records or stats.other_frames or stats.bad_crc):
        raise InputError(
            name, 0, "expected a MAVLink telemetry log: no 8-byte timestamp followed by a MAVLink frame found"
        )


def message_name(model: MavlinkClass) -> str:
    """The MAVLink name of a generated class's message (``BATTERY_STATUS``)."""
    return model.QUALIFIED_NAME.rpartition(".")[2]


def mavlink_items(
    source: Path | IO[bytes], name: str, model: MavlinkClass, *, timestamps: bool, stats: StreamStats | None = None
) -> Iterator[Item]:
    """The records of a .tlog (``timestamps``) or raw MAVLink input, then the damage summary as a
    notice (``stats``, when given, holds the counts for the caller as well)."""
    stats = stats if stats is not None else StreamStats()
    what = message_name(model)
    for rec in read_frames(source, name, model, stats, timestamps=timestamps):
        yield Record(rec.number, 0, None, name, where=rec.where(what), instance=rec.instance, location=rec.location())
    yield stats_notice(name, what, stats)


def stats_notice(name: str, what: str, stats: StreamStats) -> Notice:
    """The summary of a MAVLink input: a warning when it was damaged, else for the JSON report only."""
    text = stats.summary(what)
    if stats.problems:
        text += f" (last problem: {stats.problems[-1]})"
    return Notice(name, text, "stream", "warning" if stats.damaged else "info", stats.to_dict())
