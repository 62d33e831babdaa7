"""CAN frames from where users have them: capture files, ArduPilot DataFlash logs, live buses.

Capture files are read with python-can's log readers: candump ``.log``, Vector ``.asc`` and ``.blf``, PEAK ``.trc``
(each also gzip- or xz-compressed), and python-can's own ``.csv`` when the format is given. ArduPilot DataFlash logs
(``.bin``) carry the frames of a logged bus as CANF (classic) and CAFD (CAN FD) records, read with pymavlink's
DataFlash reader. A live bus is any python-can interface, named ``interface:channel`` (``socketcan:can0``,
``slcan:/dev/ttyACM0``, ``virtual:bus0``). python-can is an optional dependency (``pip install 'battgen[can]'``);
without it the readers say so.

Every source yields :class:`~.reassembly.Frame`\\ s in capture order, with ``t`` in seconds since the first frame;
error and remote frames come as frames of that ``kind`` (the reassembler counts and reports them). A reader's own
failure on a damaged file is an :class:`InputError` naming the file and the frame it stopped at, never a traceback.
"""

from __future__ import annotations

import importlib
import lzma
import struct
import time
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, cast

from ..dataflash.log import open_log
from ..records import InputError
from .bounded import bounded_reader, inner_suffix
from .candump_screen import read_screen, screen_stamp
from .reassembly import Frame

_FD_LENGTHS = (0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64)
_EXTENDED_FLAG = 1 << 31  # ArduPilot's CANFrame: FlagEFF, FlagRTR, FlagERR in the top bits of the id
_RTR_FLAG = 1 << 30
_ERR_FLAG = 1 << 29
NEEDS_CAN = "reading CAN captures needs python-can: pip install 'battgen[can]'"


def _python_can(name: str) -> Any:
    try:
        return importlib.import_module("can")
    except ImportError as exc:
        raise InputError(name, 0, NEEDS_CAN) from exc


CANDUMP_LINE = "a candump -l line such as '(1612543138.000000) can0 123#DEADBEEF'"
CSV_ROW = "a python-can CSV row (timestamp,arbitration_id,extended,remote,error,dlc,data)"
# text captures with one frame a line: what a line holds, and the line of the first frame (after a CSV's header)
_ONE_FRAME_A_LINE = {".log": (CANDUMP_LINE, 1), ".csv": (CSV_ROW, 2)}


def _blf_parse_error() -> type[Exception]:
    """python-can's BLF reader's own error (a bare Exception subclass), where python-can is installed."""
    try:
        from can.io.blf import BLFParseError
    except ImportError:
        return ValueError
    return cast(type[Exception], BLFParseError)


# what python-can's readers raise on a damaged capture (its BLF reader: BLFParseError, zlib.error, struct.error;
# its TRC reader: OverflowError on a start time beyond what a date or a C int holds)
_READER_ERRORS = (
    ValueError,
    ArithmeticError,
    KeyError,
    IndexError,
    TypeError,
    OSError,
    EOFError,
    AttributeError,
    zlib.error,
    lzma.LZMAError,
    struct.error,
    _blf_parse_error(),
)
_BRIEF = 160  # characters of a reader's complaint quoted (it may quote a whole hostile line)


def _brief(exc: BaseException) -> str:
    text = str(exc) or type(exc).__name__
    return text if len(text) <= _BRIEF else text[:_BRIEF] + f"... ({len(text)} characters)"


def _frames_of(
    messages: Iterator[Any], name: str, what: str, *, one_per_line: tuple[str, int] | None = None
) -> Iterator[Frame]:
    """``one_per_line``: a text capture with one frame a line (candump -l, python-can CSV): what a line holds and the
    line of the first frame, so a failure is placed on its line."""
    index = 0
    read = 0  # messages the reader gave, error and remote frames included
    t0: float | None = None
    while True:
        try:
            message = next(messages)
        except StopIteration:
            return
        except _READER_ERRORS as exc:
            # a damaged capture: the third-party reader's own complaint, located at the frame (or line) it reached
            # (the reader's exception text, "too many values to unpack", speaks of its code, not of the file)
            if one_per_line is not None:
                expected, first = one_per_line
                raise InputError(name, read + first, f"expected {expected}, found a line it cannot read") from exc
            raise InputError(name, 0, f"cannot read {what} after frame {index}: {_brief(exc)}") from exc
        read += 1
        kind = "error" if message.is_error_frame else "remote" if message.is_remote_frame else "data"
        data = bytes(message.data)
        if kind == "data" and not _fits(len(data), bool(message.is_fd)):
            kind_text = (
                "CAN FD frame (0..8, 12, 16, 20, 24, 32, 48 or 64)" if message.is_fd else "classic CAN frame (0..8)"
            )
            found = f"frame {index}: {len(data)} data bytes: expected a {kind_text}"
            raise InputError(name, read + one_per_line[1] - 1 if one_per_line else 0, found)
        stamp = float(message.timestamp or 0.0)
        if t0 is None:
            t0 = stamp
        yield Frame(
            index,
            stamp - t0,
            int(message.arbitration_id),
            b"" if kind != "data" else data,
            bool(message.is_extended_id),
            bool(message.is_fd),
            str(message.channel or ""),
            kind,
        )
        index += 1


def _fits(length: int, fd: bool) -> bool:
    """Whether a frame's data length is one its kind can carry (an FD length is one of the DLC table's)."""
    return length in _FD_LENGTHS if fd else length <= 8


def _log_reader(path: Path, name: str) -> Any:
    """python-can's log reader for the capture's suffix, fed through :mod:`.bounded` (sizes checked before they
    are trusted); InputError if it cannot open it."""
    can = _python_can(name)
    try:
        reader = bounded_reader(can, path, name)
        return reader if reader is not None else can.LogReader(str(path))
    except (*_READER_ERRORS, can.CanError) as exc:
        raise InputError(name, 0, f"cannot open the CAN capture: {_brief(exc)}") from exc


def _screen_capture(path: Path) -> float | bool | None:
    """False unless the file is candump's screen output (``can0  123  [8]  ...``, which python-can does not
    read); then the stamp of its first frame (None where candump printed none)."""
    try:
        with path.open("rb") as f:
            head = f.read(4096)
    except OSError:
        return False
    first = next((line for line in head.decode("utf-8", "replace").splitlines() if line.strip()), "")
    return screen_stamp(first)


def read_capture(path: Path, name: str) -> Iterator[Frame]:
    """The frames of a capture file read with python-can's log reader for its suffix (candump's screen output
    with :mod:`.candump_screen`)."""
    if _screen_capture(path) is not False:
        yield from read_screen(path, name)
        return
    reader = _log_reader(path, name)
    try:
        yield from _frames_of(
            iter(reader), name, "the CAN capture", one_per_line=_ONE_FRAME_A_LINE.get(inner_suffix(path))
        )
    finally:
        stop = getattr(reader, "stop", None)
        if callable(stop):
            stop()


ABSOLUTE_AFTER_S = 946_684_800.0  # 2000-01-01: a capture stamp past it is a time of day, not time since start


def capture_start(path: Path, name: str) -> float | None:
    """The Unix time (s) of a capture's first frame where its reader gives absolute stamps (candump
    logs what the kernel stamped, BLF and TRC their header's start time); None where they count from the start
    (python-can's ASC reader) or the capture is empty."""
    screen = _screen_capture(path)
    if screen is not False:
        return screen if isinstance(screen, float) and screen >= ABSOLUTE_AFTER_S else None
    reader = _log_reader(path, name)
    try:
        first = next(iter(reader), None)
    except (*_READER_ERRORS, InputError):
        return None  # the frame readers report the damage
    finally:
        stop = getattr(reader, "stop", None)
        if callable(stop):
            stop()
    stamp = float(first.timestamp or 0.0) if first is not None else 0.0
    return stamp if stamp >= ABSOLUTE_AFTER_S else None


def read_dataflash_frames(path: Path, name: str) -> Iterator[Frame]:
    """The CAN frames an ArduPilot DataFlash log recorded: its CANF (classic) and CAFD (CAN FD) records, laid out
    as ``libraries/AP_CANManager/LogStructure.h`` declares them (``Id`` with AP_HAL's flag bits on top; CAFD's
    ``DLC`` a data length code and its data in eight 64-bit words)."""
    index = 0
    t0: int | None = None
    for record in open_log(path, name).messages(("CANF", "CAFD")):
        values = record.fields
        try:
            raw_id = int(values["Id"])
            kind = "error" if raw_id & _ERR_FLAG else "remote" if raw_id & _RTR_FLAG else "data"
            if kind != "data":
                data = b""
            elif record.type == "CAFD":
                words = b"".join((int(values[f"D{i}"]) & (2**64 - 1)).to_bytes(8, "little") for i in range(8))
                data = words[: _FD_LENGTHS[int(values["DLC"]) & 0xF]]
            else:
                data = bytes(int(values[f"B{i}"]) & 0xFF for i in range(8))[: max(0, min(int(values["DLC"]), 8))]
            bus = int(values.get("Bus", 0))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(name, 0, f"{record.type} record {record.index}: expected CAN frame fields: {exc}") from exc
        stamp = record.time_us or 0
        if t0 is None:
            t0 = stamp
        yield Frame(
            index,
            (stamp - t0) / 1e6,
            raw_id & 0x1FFFFFFF,
            data,
            bool(raw_id & _EXTENDED_FLAG),
            record.type == "CAFD",
            f"bus{bus}",
            kind,
        )
        index += 1


def read_bus(
    spec: str, *, duration: float | None = None, clock: Callable[[], float] = time.monotonic
) -> Iterator[Frame]:
    """Frames from a live python-can bus named ``interface:channel`` until ``duration`` seconds have passed
    (forever when None; the caller stops on Ctrl-C). The bus is shut down however the iteration ends."""
    interface, sep, channel = spec.partition(":")
    if not sep or not interface or not channel:
        raise InputError(spec, 0, "expected a bus as interface:channel, e.g. socketcan:can0 or slcan:/dev/ttyACM0")
    can = _python_can(spec)
    try:
        options = {"fd": True} if interface == "socketcan" else {}  # CAN FD frames too, where the driver can
        bus = can.Bus(interface=interface, channel=channel, **options)
    except Exception as exc:  # python-can raises many kinds (CanInterfaceNotImplementedError, OSError, ...)
        raise InputError(spec, 0, f"cannot open the CAN bus: {exc}") from exc
    try:
        yield from _frames_of(_receive(bus, duration, clock), spec, "the CAN bus")
    finally:
        bus.shutdown()


def _receive(bus: Any, duration: float | None, clock: Callable[[], float]) -> Iterator[Any]:
    """Messages from ``bus`` until ``duration`` seconds have passed; polls in 0.1 s steps so the end is timely."""
    start = clock()
    while duration is None or clock() - start < duration:
        message = bus.recv(timeout=0.1)
        if message is not None:
            yield message
