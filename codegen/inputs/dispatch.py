"""Choosing the reader of a data file: its kind from the extension (or given), then the records.

Kinds: JSON (.json), JSON Lines (.jsonl/.ndjson), YAML (.yaml/.yml), devicetree source
(.dts/.dtsi) and blobs (.dtb), parameter files (.param/.parm/.params), PX4 ULog (.ulg), MAVLink
telemetry logs (.tlog), raw MAVLink streams (.mav), CAN bus captures (candump .log, .asc, .blf, .trc, also
gzip-compressed) and the CAN frames of ArduPilot DataFlash logs (.bin) for DroneCAN messages.
The text kinds hold plain data for any message; the others hold one source format's messages, and
the binary ones are decoded by the message's generated class.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ..ir import Message, SourceFormat
from .can.captures import CAPTURE_SUFFIXES, DATAFLASH_SUFFIXES, is_capture
from .can.records import capture_items
from .devicetree.records import read_devicetree
from .documents import read_json, read_jsonl, read_yaml
from .model import MavlinkClass, MessageClass
from .parameter_records import read_parameter_records
from .records import InputError, Item
from .tlog import mavlink_items
from .ulog import ulog_items

JSON_SUFFIXES = frozenset({".json"})
JSONL_SUFFIXES = frozenset({".jsonl", ".ndjson"})
YAML_SUFFIXES = frozenset({".yaml", ".yml"})
DTS_SUFFIXES = frozenset({".dts", ".dtsi"})
DTB_SUFFIXES = frozenset({".dtb"})
PARAM_SUFFIXES = frozenset({".param", ".parm", ".params"})
ULOG_SUFFIXES = frozenset({".ulg"})
TLOG_SUFFIXES = frozenset({".tlog"})
MAVLINK_SUFFIXES = frozenset({".mav"})  # not .bin: that is ArduPilot's DataFlash log
KNOWN_SUFFIXES = JSON_SUFFIXES | JSONL_SUFFIXES | YAML_SUFFIXES | DTS_SUFFIXES | DTB_SUFFIXES
KNOWN_SUFFIXES |= (
    PARAM_SUFFIXES | ULOG_SUFFIXES | TLOG_SUFFIXES | MAVLINK_SUFFIXES | CAPTURE_SUFFIXES | DATAFLASH_SUFFIXES
)
_KINDS = (
    ("json", JSON_SUFFIXES),
    ("jsonl", JSONL_SUFFIXES),
    ("yaml", YAML_SUFFIXES),
    ("dts", DTS_SUFFIXES),
    ("dtb", DTB_SUFFIXES),
    ("param", PARAM_SUFFIXES),
    ("ulog", ULOG_SUFFIXES),
    ("tlog", TLOG_SUFFIXES),
    ("mavlink", MAVLINK_SUFFIXES),
    ("can", CAPTURE_SUFFIXES),
    ("dataflash", DATAFLASH_SUFFIXES),
)
KINDS = tuple(kind for kind, _ in _KINDS)
# the source format a file kind holds; the text kinds hold any
KIND_FORMATS: dict[str, SourceFormat] = {
    "dts": SourceFormat.DEVICETREE,
    "dtb": SourceFormat.DEVICETREE,
    "param": SourceFormat.PDEF,
    "ulog": SourceFormat.UORB,
    "tlog": SourceFormat.MAVLINK,
    "mavlink": SourceFormat.MAVLINK,
    "can": SourceFormat.DRONECAN,
}
_HOLDS = {
    "dts": "a devicetree file holds devicetree nodes",
    "dtb": "a devicetree file holds devicetree nodes",
    "param": "a parameter file holds parameters",
    "ulog": "a ULog file holds uORB topics",
    "tlog": "a MAVLink log holds MAVLink messages",
    "mavlink": "a MAVLink log holds MAVLink messages",
    "can": "a CAN capture holds DroneCAN messages",
}


def kind_of_suffix(path: Path) -> str | None:
    """The data kind (one of KINDS) a file name's extension says, if any."""
    if is_capture(path):  # looks through .gz
        return "can"
    suffix = path.suffix.lower()
    for kind, suffixes in _KINDS:
        if suffix in suffixes:
            return kind
    return None


def file_kind(path: Path) -> str:
    """The data kind (one of KINDS) from the file name's extension; InputError when it says none."""
    kind = kind_of_suffix(path)
    if kind is not None:
        return kind
    known = ", ".join(sorted(KNOWN_SUFFIXES))
    raise InputError(
        path.as_posix(),
        0,
        f"cannot tell the data format from the extension (expected one of {known}, or give --input-format)",
    )


def read_records(
    path: Path,
    message: Message,
    display: str | None = None,
    *,
    model: MessageClass | None = None,
    kind: str | None = None,
) -> Iterator[Item]:
    """The records of one data file for ``message``, in file order. Raises InputError (or another
    LocatedError) when the file is unreadable. ``model`` is the generated class of ``message``:
    parameter files and binary logs need it; ``kind`` overrides the kind the extension says."""
    name = display if display is not None else path.as_posix()
    kind = kind or file_kind(path)
    if kind == "dataflash" and message.format is SourceFormat.DRONECAN:
        kind = "can"  # a DataFlash log's CANF/CAFD records: the frames of a logged CAN bus
    if kind in ("param", "ulog", "tlog", "mavlink", "can") and model is None:
        raise InputError(name, 0, f"reading {kind} input needs the generated class of {message.qualified_name}")
    expected = KIND_FORMATS.get(kind)
    if expected is not None and message.format is not expected:
        raise InputError(name, 0, f"{_HOLDS[kind]}, but {message.qualified_name} is a {message.format.value} message")
    if model is not None and kind == "can":
        return capture_items(path, name, model)
    if kind == "dataflash":
        raise InputError(
            name,
            0,
            f"a DataFlash log is read here for the DroneCAN messages of its CAN frames; "
            f"{message.qualified_name} is a {message.format.value} message",
        )
    if kind in ("dts", "dtb"):
        return read_devicetree(path, name, message, binary=kind == "dtb")
    if model is not None and kind == "param":
        return read_parameter_records(path, name, model)
    if model is not None and kind == "ulog":
        return ulog_items(path, name, model)
    if model is not None and kind in ("tlog", "mavlink"):
        if not isinstance(model, MavlinkClass):
            raise InputError(name, 0, f"{model.QUALIFIED_NAME} has no MAVLink codec: run 'battgen generate'")
        return mavlink_items(path, name, model, timestamps=kind == "tlog")
    if kind == "jsonl":
        return read_jsonl(path, name)
    if kind == "yaml":
        return read_yaml(path, name)
    return read_json(path, name)
