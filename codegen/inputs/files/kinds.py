"""What kind of data a file holds: one detection for every command, content first, then the name.

The kinds, one vocabulary for every command and message, and what tells each (content first):

- ``ulog``: PX4 ULog; the magic ``ULog\\x01\\x12\\x35``, else ``.ulg``.
- ``dataflash``: ArduPilot DataFlash log, binary or text; ``A3 95 80`` (the FMT record of FMT) or ``FMT, ...``
  lines near the top, else ``.bin``.
- ``tlog``: MAVLink telemetry log (a µs stamp before each frame); a plausible big-endian stamp, then a MAVLink
  magic, else ``.tlog``.
- ``mavlink``: a raw MAVLink byte stream; ``.mav``.
- ``can``: a CAN capture (candump log or screen output, Vector ASC/BLF, PEAK TRC, gzip or xz of them); ``LOGG`` (BLF),
  candump/ASC/TRC lines, else ``.log``, ``.asc``, ``.blf``, ``.trc`` (also inside ``.gz`` or ``.xz``).
- ``dtb``: a devicetree blob; the FDT magic ``D0 0D FE ED``, else ``.dtb``. ``dts``: ``/dts-v1/``, else ``.dts``,
  ``.dtsi``.
- ``param`` (``.param``, ``.parm``, QGroundControl ``.params``), ``json``, ``jsonl``, ``yaml``: by the name.

Content wins over the name where the content is unambiguous: a tlog named ``fs-batt.log`` is a tlog, a text
DataFlash log named ``.log`` is not a CAN capture. The text kinds (JSON, JSON Lines, YAML, parameter files)
carry no signature that sets them apart reliably, so their names decide.
"""

from __future__ import annotations

import re
import struct
from pathlib import Path

from ..records import InputError

KINDS = ("json", "jsonl", "yaml", "dts", "dtb", "param", "ulog", "tlog", "mavlink", "can", "dataflash")
# the flight logs and captures: a clock and context of their own, read by every log command through the battery
# view (codegen.apps.battery); a JSON Lines file of battery records is read by it too, as plain data
FLIGHT_LOG_KINDS = ("ulog", "tlog", "dataflash", "can")
LOG_KINDS = (*FLIGHT_LOG_KINDS, "jsonl")
# how a message of another source format than the kind holds is refused (the formats themselves:
# kind_formats.py, apart, so that telling a file's kind does not import the IR)
KIND_HOLDS = {
    "dts": "a devicetree file holds devicetree nodes",
    "dtb": "a devicetree file holds devicetree nodes",
    "param": "a parameter file holds parameters",
    "ulog": "a ULog file holds uORB topics",
    "tlog": "a MAVLink log holds MAVLink messages",
    "mavlink": "a MAVLink log holds MAVLink messages",
    "can": "a CAN capture holds DroneCAN messages",
}

SUFFIXES: dict[str, frozenset[str]] = {
    "json": frozenset({".json"}),
    "jsonl": frozenset({".jsonl", ".ndjson"}),
    "yaml": frozenset({".yaml", ".yml"}),
    "dts": frozenset({".dts", ".dtsi"}),
    "dtb": frozenset({".dtb"}),
    "param": frozenset({".param", ".parm", ".params"}),
    "ulog": frozenset({".ulg"}),
    "tlog": frozenset({".tlog"}),
    "mavlink": frozenset({".mav"}),  # not .bin: that is ArduPilot's DataFlash log
    "can": frozenset({".log", ".asc", ".blf", ".trc"}),
    "dataflash": frozenset({".bin"}),
}
KNOWN_SUFFIXES = frozenset().union(*SUFFIXES.values())
# a CAN capture may come compressed (bus.log.gz, bus.blf.xz): these are looked through to the capture's own suffix
COMPRESSED_SUFFIXES = frozenset({".gz", ".xz"})

ULOG_MAGIC = b"ULog\x01\x12\x35"
DATAFLASH_MAGIC = b"\xa3\x95\x80"  # a message header and type 128: the FMT record describing FMT
DTB_MAGIC = b"\xd0\x0d\xfe\xed"
BLF_MAGIC = b"LOGG"
MAVLINK_MAGICS = (0xFE, 0xFD)  # MAVLink 1, MAVLink 2
# a tlog stamp (µs since the epoch) from 2000 to 2100: a random file starts with one by chance once in ~2^20
_TLOG_STAMPS = (946_684_800_000_000, 4_102_444_800_000_000)
_HEAD = 4096
_CANDUMP = re.compile(rb"\s*\(\d+\.\d+\)\s+\S+\s+[0-9A-Fa-f]+(#|\s+\[\d+\])")  # -l: ID#DATA; screen -ta: ID  [n]
_CANDUMP_SCREEN = re.compile(rb"\s*\S+\s+[0-9A-Fa-f]{3,8}\s+\[\d+\]")  # plain screen output:  can0  123  [8]  ...
_ASC = re.compile(rb"\s*(date|base\s+(hex|dec)|;\s*\$?FILEVERSION|;\s*Start time)", re.IGNORECASE)


def capture_suffix(path: Path) -> str:
    """The suffix of a file name, looking through a ``.gz`` or ``.xz`` (``bus.asc.gz`` -> ``.asc``)."""
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes and suffixes[-1] in COMPRESSED_SUFFIXES:
        suffixes.pop()
    return suffixes[-1] if suffixes else ""


def kind_of_name(path: Path) -> str | None:
    """The kind a file's name says, if any (a ``.gz`` or ``.xz`` is looked through for captures)."""
    suffix = path.suffix.lower()
    if suffix in COMPRESSED_SUFFIXES:
        return "can" if capture_suffix(path) in SUFFIXES["can"] else None
    for kind, suffixes in SUFFIXES.items():
        if suffix in suffixes:
            return kind
    return None


def kind_of_content(head: bytes) -> str | None:
    """The kind the first bytes of a file say, where they say it unambiguously."""
    if head.startswith(ULOG_MAGIC):
        return "ulog"
    if head.startswith(DATAFLASH_MAGIC):
        return "dataflash"
    if head.startswith(DTB_MAGIC):
        return "dtb"
    if head.startswith(BLF_MAGIC):
        return "can"
    if len(head) >= 9 and head[8] in MAVLINK_MAGICS:
        (stamp,) = struct.unpack(">Q", head[:8])
        if _TLOG_STAMPS[0] <= stamp <= _TLOG_STAMPS[1]:
            return "tlog"
    lines = _text_lines(head)
    if not lines:
        return None
    # a text DataFlash log: FMT lines near the top (ArduPilot 3.0's start with a few lines of banner)
    if any(line.startswith((b"FMT,", b"FMT ,")) for line in lines):
        return "dataflash"
    first = lines[0]
    if first.lstrip().startswith(b"/dts-v1/"):
        return "dts"
    if _CANDUMP.match(first) or _CANDUMP_SCREEN.match(first) or _ASC.match(first):
        return "can"
    return None


def _text_lines(head: bytes) -> list[bytes]:
    """The lines with text of a head that looks like text (none for binary data), the last (maybe cut) left out
    unless it is the only one."""
    if b"\0" in head:
        return []
    lines = [line.strip().lstrip(b"\xef\xbb\xbf") for line in head.splitlines()]
    if len(head) == _HEAD and len(lines) > 1:
        lines.pop()
    return [line for line in lines if line]


def content_kind(path: Path) -> str | None:
    """The kind a file's first bytes say (None where they say none, or the file cannot be opened)."""
    try:
        with path.open("rb") as f:
            head = f.read(_HEAD)
    except OSError:
        return None
    return kind_of_content(head)


def detect(path: Path) -> str | None:
    """The kind of a file: its content where that tells, else its name; None when neither does. A file
    that cannot be opened is told by its name (the reader then says why it cannot read it)."""
    return content_kind(path) or kind_of_name(path)


def file_kind(path: Path) -> str:
    """The kind of a file (:func:`detect`); an InputError naming the file when nothing tells it."""
    kind = detect(path)
    if kind is not None:
        return kind
    known = ", ".join(sorted(KNOWN_SUFFIXES))
    raise InputError(
        path.as_posix(),
        0,
        f"cannot tell the data format from the content or the extension (expected one of {known}, "
        "or give --input-format)",
    )
