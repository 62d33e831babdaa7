"""Choosing the reader of a data file: its kind (:mod:`.kinds`: the content, then the name; or given), then the
records.

Kinds: JSON, JSON Lines, YAML, devicetree source and blobs, parameter files, PX4 ULog, MAVLink telemetry logs,
raw MAVLink streams, CAN bus captures and the CAN frames of ArduPilot DataFlash logs for DroneCAN messages.
The text kinds hold plain data for any message; the others hold one source format's messages, and
the binary ones are decoded by the message's generated class.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

from ..ir import Message, SourceFormat
from .documents import read_json, read_jsonl, read_yaml
from .files.kind_formats import KIND_FORMATS
from .files.kinds import KIND_HOLDS, file_kind
from .model import MavlinkClass, MessageClass
from .records import InputError, Item

# The readers of the binary and devicetree kinds are imported in their branch below: a run reads one kind, and
# the CAN captures' reader alone brings python-can, the devicetree one the devicetree frontend.


def read_records(
    path: Path,
    message: Message,
    display: str | None = None,
    *,
    model: MessageClass | None = None,
    kind: str | None = None,
    subjects: Sequence[str] = (),
) -> Iterator[Item]:
    """The records of one data file for ``message``, in file order. Raises InputError (or another
    LocatedError) when the file is unreadable. ``model`` is the generated class of ``message``:
    parameter files and binary logs need it; ``kind`` overrides the kind the extension says; ``subjects``: the
    ``ID=TYPE`` pairs that say which subject of a Cyphal/CAN capture carries which type."""
    name = display if display is not None else path.as_posix()
    kind = kind or file_kind(path)
    if kind == "dataflash" and message.format is SourceFormat.DRONECAN:
        kind = "can"  # a DataFlash log's CANF/CAFD records: the frames of a logged CAN bus
    if kind in ("param", "ulog", "tlog", "mavlink", "can") and model is None:
        raise InputError(name, 0, f"reading {kind} input needs the generated class of {message.qualified_name}")
    expected = KIND_FORMATS.get(kind)
    cyphal_capture = kind == "can" and message.format is SourceFormat.CYPHAL  # Cyphal/CAN: a CAN capture too
    if expected is not None and message.format is not expected and not cyphal_capture:
        raise InputError(
            name, 0, f"{KIND_HOLDS[kind]}, but {message.qualified_name} is a {message.format.value} message"
        )
    if model is not None and kind == "can":
        from .can.records import capture_items

        return capture_items(path, name, model, subjects)
    if kind == "dataflash":
        raise InputError(
            name,
            0,
            f"a DataFlash log is read here for the DroneCAN messages of its CAN frames; "
            f"{message.qualified_name} is a {message.format.value} message",
        )
    if kind in ("dts", "dtb"):
        from .devicetree.records import read_devicetree

        return read_devicetree(path, name, message, binary=kind == "dtb")
    if model is not None and kind == "param":
        from .parameters.records import read_parameter_records

        return read_parameter_records(path, name, model)
    if model is not None and kind == "ulog":
        from .ulog.records import ulog_items

        return ulog_items(path, name, model)
    if model is not None and kind in ("tlog", "mavlink"):
        if not isinstance(model, MavlinkClass):
            raise InputError(name, 0, f"{model.QUALIFIED_NAME} has no MAVLink codec: run 'battgen generate'")
        from .tlog import mavlink_items

        return mavlink_items(path, name, model, timestamps=kind == "tlog")
    if kind == "jsonl":
        return read_jsonl(path, name)
    if kind == "yaml":
        return read_yaml(path, name)
    return read_json(path, name)
