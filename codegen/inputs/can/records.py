"""The DroneCAN messages of a CAN capture as records, with the capture's transport diagnostics as notices.

:func:`capture_items` reads a capture (or a DataFlash log's CAN frames), reassembles every transfer, checks each
multi-frame transfer's CRC against the signatures of all the DroneCAN types the generated package knows, and
hands out one record per transfer of the asked-for message, decoded by its generated class, located by time,
frame index and source node (every battery node separately: ``location["node"]``). Transport problems become
notices (``kind="transport"``, severity ``error`` for damage, ``warning`` for skipped transfer ids), each naming
the frame's time and position; a capture-wide summary (frames, transfers, nodes and their rates) ends the stream.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import cast

from ..files.kinds import detect
from ..model import CyphalClass, DronecanClass, GeneratedMessage, MessageClass, package_name
from ..records import InputError, Item, Notice, Record, Unreadable
from .captures import read_capture, read_dataflash_frames
from .cyphal_ports import cyphal_classes, dsdl_name, subject_table
from .cyphal_reassembly import cyphal_hint, reassembler_for
from .ordering import AuxOrder
from .reassembly import Diagnostic, Frame, Transfer

MAX_NOTICES_PER_CODE = 50  # a damaged bus repeats itself: the rest of each kind is counted, not listed
Registry = dict[tuple[str, int], DronecanClass]


def type_kind(cls: DronecanClass) -> str:
    """``request`` / ``response`` for the halves of a service (generated as ``<Name>.Request`` / ``.Response``),
    else ``message``: the same words as :attr:`~.wire.CanId.kind`."""
    for half in ("Request", "Response"):
        if cls.QUALIFIED_NAME.endswith("." + half):
            return half.lower()
    return "message"


def signatures(known: Registry) -> dict[tuple[str, int], int]:
    """The transfer CRC seeds the reassembler needs, by (``message`` | ``service``, id)."""
    return {
        ("message" if kind == "message" else "service", type_id): cls.DATA_TYPE_SIGNATURE
        for (kind, type_id), cls in known.items()
    }


@functools.cache
def registry(package: str) -> Registry:
    """Every DroneCAN class with a data type id in a generated package, by (kind, id): ``message``, or
    ``request`` / ``response`` for the two halves of a service, which share the service's id."""
    found: Registry = {}
    try:
        root = importlib.import_module(package + ".dronecan")
    except ImportError:
        return found
    modules = [root] + [
        importlib.import_module(info.name) for info in pkgutil.walk_packages(root.__path__, root.__name__ + ".")
    ]
    for module in modules:
        for value in vars(module).values():
            if isinstance(value, type) and isinstance(value, DronecanClass) and value.DATA_TYPE_ID is not None:
                if value.__module__ == module.__name__:
                    found.setdefault((type_kind(value), value.DATA_TYPE_ID), value)
    return found


FD_MAX_PADDING = 15  # bytes: the largest gap between two CAN FD data lengths (48 -> 64) less one


def decode_transfer(cls: DronecanClass, transfer: Transfer) -> GeneratedMessage:
    """A transfer's message. Classic CAN payloads use tail-array optimisation; a CAN FD transfer does not, and
    its last frame is padded with zero bytes up to a valid data length, which the message does not say: the
    padding is cut back until the payload decodes (the content is the same whichever length succeeds)."""
    if not transfer.fd:
        return cls.decode(transfer.payload, tao=True)
    payload = transfer.payload
    error: ValueError | None = None
    for cut in range(min(FD_MAX_PADDING, len(payload)) + 1):
        if cut and payload[-cut] != 0:
            break
        try:
            return cls.decode(payload[: len(payload) - cut], tao=False)
        except ValueError as exc:  # the generated DecodeError
            error = exc
    assert error is not None
    raise error


def frames_of(path: Path, name: str, kind: str | None = None) -> Iterator[Frame]:
    """The frames of a capture file or of a DataFlash log's CANF/CAFD records; ``kind`` (``can`` or
    ``dataflash``, as ``--input-format`` gives it) overrides what the file's name and content say."""
    if (kind or detect(path)) == "dataflash":
        return read_dataflash_frames(path, name)
    return read_capture(path, name)


def _where(transfer: Transfer) -> str:
    return f"node {transfer.node} at t={transfer.t:.6f} s, frame {transfer.frame}"


class _Notices:
    """Turns diagnostics into notices, listing the first few of each code and counting the rest."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.counts: Counter[str] = Counter()

    def notice(self, diag: Diagnostic) -> Notice | None:
        self.counts[diag.code] += 1
        if self.counts[diag.code] > MAX_NOTICES_PER_CODE:
            return None
        text = f"t={diag.t:.6f} s, frame {diag.frame}: {diag.message} [{diag.code}]"
        return Notice(self.name, text, "transport", diag.severity, diag.to_dict())

    def overflow(self) -> list[Notice]:
        return [
            Notice(self.name, f"{n - MAX_NOTICES_PER_CODE} more {code} problem(s) not listed", "transport", "warning")
            for code, n in sorted(self.counts.items())
            if n > MAX_NOTICES_PER_CODE
        ]


def capture_items(path: Path, name: str, model: MessageClass, subjects: Sequence[str] = ()) -> Iterator[Item]:
    """The records of ``model``'s message in a CAN capture, with transport notices and a closing summary."""
    return capture_side(path, name, [model], subjects)


def capture_side(path: Path, name: str, models: Sequence[MessageClass], subjects: Sequence[str] = ()) -> Iterator[Item]:
    """The records of ``models[0]``'s message in a CAN capture, each with the same node's latest message of each
    other model as its ``companions`` (None until the node sent one): BatteryInfo with its node's BatteryInfoAux,
    paired the way PX4's bridge pairs them. Cyphal messages are read from the subjects ``subjects`` (``ID=TYPE``
    pairs, :func:`.cyphal_ports.subject_table`) gives them, on a bus read as DroneCAN and Cyphal/CAN."""
    if models and isinstance(models[0], CyphalClass):
        return _cyphal_side(path, name, models, subjects)
    classes = []
    for model in models:
        if not isinstance(model, DronecanClass) or model.DATA_TYPE_ID is None:
            raise InputError(
                name, 0, f"a CAN capture holds DroneCAN messages with a data type id; {model.QUALIFIED_NAME} has none"
            )
        classes.append(model)
    wanted = {
        ("dronecan", c.DATA_TYPE_ID or 0): i for i, c in reversed(list(enumerate(classes))) if type_kind(c) == "message"
    }
    return _items(frames_of(path, name), name, classes, wanted, "dronecan")


def _cyphal_side(path: Path, name: str, models: Sequence[MessageClass], subjects: Sequence[str]) -> Iterator[Item]:
    classes: list[CyphalClass] = []
    for model in models:
        if not isinstance(model, CyphalClass):
            raise InputError(
                name, 0, f"a Cyphal capture's companions are Cyphal messages; {model.QUALIFIED_NAME} is not"
            )
        classes.append(model)
    table = subject_table(subjects, cyphal_classes(package_name(classes[0])))
    wanted = {("cyphal", port): classes.index(cls) for port, cls in table.items() if cls in classes}
    if not any(position == 0 for position in wanted.values()):
        raise InputError(
            name,
            0,
            f"Cyphal/CAN frames name subjects, not types: expected --cyphal-subject ID={dsdl_name(classes[0])} "
            "(the subject id the node publishes it on)",
        )
    return _items(frames_of(path, name), name, classes, wanted, "mixed")


def transfer_items(frames: Iterable[Frame], name: str, model: DronecanClass) -> Iterator[Item]:
    """As :func:`capture_items`, for frames from anywhere (a live bus)."""
    return _items(iter(frames), name, [model], {("dronecan", model.DATA_TYPE_ID or 0): 0}, "dronecan")


def _decoder(cls: MessageClass) -> Callable[[Transfer], GeneratedMessage]:
    """How a transfer of ``cls`` is read: a DroneCAN one as :func:`decode_transfer` does, a Cyphal one whole
    (padding past the last field is ignored, as Cyphal's implicit extension has it)."""
    if isinstance(cls, DronecanClass):
        return functools.partial(decode_transfer, cls)
    cyphal = cast(CyphalClass, cls)
    return lambda transfer: cyphal.decode(transfer.payload)


def _items(
    frames: Iterator[Frame],
    name: str,
    classes: Sequence[MessageClass],
    wanted: dict[tuple[str, int], int],
    transport: str,
) -> Iterator[Item]:
    """``wanted``: the position in ``classes`` of each (protocol, data type id or subject id) read."""
    model = classes[0]
    known = registry(package_name(model))
    seeds = signatures(known)
    for cls in classes:
        if isinstance(cls, DronecanClass):
            seeds.setdefault(("message", cls.DATA_TYPE_ID or 0), cls.DATA_TYPE_SIGNATURE)
    reassembler = reassembler_for(transport, seeds)
    decoders = [_decoder(cls) for cls in classes]
    order = AuxOrder(known)
    notices = _Notices(name)
    latest: dict[tuple[int, int], GeneratedMessage] = {}  # (node, position in classes) -> its last message
    per_node: Counter[int] = Counter()
    index = 0
    last = Frame(0, 0.0, 0, b"")
    for frame in frames:
        last = frame
        for event in reassembler.feed(frame):
            if isinstance(event, Diagnostic):
                note = notices.notice(event)
                if note is not None:
                    yield note
                continue
            for diag in order.see(event):
                note = notices.notice(diag)
                if note is not None:
                    yield note
            position = None if event.id.service else wanted.get((event.id.protocol, event.id.data_type_id))
            if position is None:
                continue
            cls = classes[position]
            try:
                instance = decoders[position](event)
            except ValueError as exc:  # the generated DecodeError: bytes that are not this message
                yield Unreadable(name, 0, f"{_where(event)}: cannot decode {cls.QUALIFIED_NAME}: {exc}")
                continue
            if position:
                latest[(event.node, position)] = instance
                continue
            per_node[event.node] += 1
            yield Record(
                index,
                0,
                None,
                name,
                where=_where(event),
                instance=instance,
                location={"t": event.t, "frame": event.frame, "node": event.node, "transfer_id": event.transfer_id},
                companions=tuple(latest.get((event.node, i)) for i in range(1, len(classes))),
            )
            index += 1
    hint = cyphal_hint(reassembler, last.t, last.index)
    for diag in reassembler.finish(last.t, last.index) + ([hint] if hint is not None else []):
        note = notices.notice(diag)
        if note is not None:
            yield note
    yield from notices.overflow()
    if reassembler.frames == 0:
        yield Notice(name, "no CAN frames in this capture", "empty", "error")  # empty input is not success
        return
    nodes = ", ".join(f"node {n}: {c}" for n, c in sorted(per_node.items())) or "none"
    summary = (
        f"{reassembler.frames} frames, {reassembler.transfers} transfers; "
        f"{model.QUALIFIED_NAME} records per node: {nodes}"
    )
    yield Notice(name, summary, "stream", "info", {"frames": reassembler.frames, "nodes": dict(per_node)})
    if index == 0:
        yield Notice(name, f"no {model.QUALIFIED_NAME} transfers in this capture", "empty")
