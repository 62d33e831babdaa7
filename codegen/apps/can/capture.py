"""What a CAN capture (or a live bus) holds: nodes, data types and their rates, transport problems.

The engine behind ``battgen can``: every frame is reassembled (:mod:`codegen.inputs.can.reassembly`), each transfer
is counted per (node, data type) and, when it is a type the generated package knows, decoded (a decode failure is
a problem too); transport diagnostics and the BatteryInfoAux order check are collected per code. The report keeps
counts and the first few problems of each kind, so its memory is flat in the capture's length.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import cast

from ...inputs.can.cyphal_ports import Subjects, dsdl_name
from ...inputs.can.cyphal_reassembly import cyphal_hint, reassembler_for
from ...inputs.can.ordering import AuxOrder
from ...inputs.can.reassembly import Diagnostic, Frame, Transfer
from ...inputs.can.records import Registry, decode_transfer, signatures
from ...inputs.model import CyphalClass, DronecanClass, GeneratedMessage
from .known_types import TypeTable

KEEP_PER_CODE = 20  # problems listed per code; the rest are counted


@dataclass
class Stream:
    """The transfers of one (node, kind, data type or port, protocol) seen in a capture."""

    node: int
    kind: str  # message, request, response; a Cyphal message's is "subject"
    data_type_id: int  # a Cyphal transfer's port id
    name: str  # the DSDL name where the generated package knows the type, else ""
    count: int = 0
    first_t: float = 0.0
    last_t: float = 0.0
    undecodable: int = 0
    span: float = 0.0  # seconds between successive transfers where the clock went forward
    steps: int = 0  # those intervals: a clock that jumps back breaks the count into monotonic stretches
    protocol: str = "dronecan"

    def see(self, t: float) -> None:
        """One more transfer at ``t``."""
        if self.count and t >= self.last_t:
            self.span += t - self.last_t
            self.steps += 1
        self.count += 1
        self.last_t = t

    @property
    def rate(self) -> float:
        """Transfers per second over the stretches where the capture's clock ran forward (0 for a single one)."""
        return self.steps / self.span if self.steps and self.span > 0 else 0.0

    def to_dict(self) -> dict[str, object]:
        return {
            "protocol": self.protocol,
            "node": self.node,
            "kind": self.kind,
            "data_type_id": self.data_type_id,
            "name": self.name,
            "count": self.count,
            "rate_hz": round(self.rate, 3),
            "undecodable": self.undecodable,
        }


@dataclass
class CaptureReport:
    """The whole account of one capture."""

    source: str
    frames: int = 0
    transfers: int = 0
    duration: float = 0.0
    streams: dict[tuple[int, str, int, str], Stream] = field(default_factory=dict)
    counts: Counter[str] = field(default_factory=Counter)  # problems per code
    problems: list[Diagnostic] = field(default_factory=list)  # the first KEEP_PER_CODE of each code
    severities: dict[str, str] = field(default_factory=dict)  # code -> severity

    @property
    def errors(self) -> int:
        """Transport damage found (warnings such as skipped transfer ids and info notes not counted)."""
        return sum(n for code, n in self.counts.items() if self.severities.get(code) == "error")

    def to_dict(self) -> dict[str, object]:
        return {
            "source": self.source,
            "frames": self.frames,
            "transfers": self.transfers,
            "duration_s": round(self.duration, 6),
            "streams": [s.to_dict() for _, s in sorted(self.streams.items())],
            "problem_counts": dict(sorted(self.counts.items())),
            "problems": [d.to_dict() for d in self.problems],
        }


def scan(
    frames: Iterable[Frame],
    source: str,
    known: Registry,
    *,
    on_message: Callable[[Transfer, GeneratedMessage], None] | None = None,
    standard: TypeTable | None = None,
    transport: str = "dronecan",
    subjects: Subjects | None = None,
) -> CaptureReport:
    """Account for every frame; ``on_message`` is called with each decoded transfer of a known type.
    ``standard``: more types (:func:`.can_types.standard_types`) whose transfers are named and CRC-checked.
    ``transport``: ``dronecan``, ``cyphal`` or ``mixed`` (both on one bus); ``subjects``: the Cyphal type of
    each subject id (:func:`~codegen.inputs.can.cyphal_ports.subject_table`), decoded as DroneCAN types are."""
    seeds = signatures(known)
    for (kind, type_id), (_, signature) in (standard or {}).items():
        seeds.setdefault(("message" if kind == "message" else "service", type_id), signature)
    reassembler = reassembler_for(transport, seeds)
    order = AuxOrder(known)
    report = CaptureReport(source)
    last: Frame | None = None

    def note(diag: Diagnostic) -> None:
        report.counts[diag.code] += 1
        report.severities[diag.code] = diag.severity
        if report.counts[diag.code] <= KEEP_PER_CODE:
            report.problems.append(diag)

    forward = 0.0  # seconds the clock ran forward: the capture's duration, however often it jumped back
    for frame in frames:
        if last is not None:
            if frame.t < last.t:
                note(
                    Diagnostic("can-clock-back", _clock_back(last.t, frame.t), frame.t, frame.index, severity="warning")
                )
            else:
                forward += frame.t - last.t
        last = frame
        for event in reassembler.feed(frame):
            if isinstance(event, Diagnostic):
                note(event)
                continue
            for diag in order.see(event):
                note(diag)
            _count(report, event, _types(event, known, subjects or {}), note, on_message, standard or {})
    if last is not None:
        for diag in reassembler.finish(last.t, last.index):
            note(diag)
        report.duration = forward
        hint = cyphal_hint(reassembler, last.t, last.index)
        if hint is not None:
            note(hint)
    report.frames = reassembler.frames
    report.transfers = reassembler.transfers
    return report


def _clock_back(before: float, now: float) -> str:
    return (
        f"the capture's clock went back {before - now:.6f} s (from {before:.6f} s to {now:.6f} s): "
        "rates and the duration count only where it ran forward"
    )


def _types(transfer: Transfer, known: Registry, subjects: Subjects) -> tuple[DronecanClass | CyphalClass | None, str]:
    """The generated class of a transfer's type, where known, and its DSDL name."""
    if transfer.id.protocol == "cyphal":
        found = subjects.get(transfer.id.data_type_id) if not transfer.id.service else None
        return found, dsdl_name(found) if found is not None else ""
    cls = known.get((transfer.id.kind, transfer.id.data_type_id))
    return cls, cls.QUALIFIED_NAME.removeprefix("dronecan.") if cls is not None else ""


def _count(
    report: CaptureReport,
    transfer: Transfer,
    typed: tuple[DronecanClass | CyphalClass | None, str],
    note: Callable[[Diagnostic], None],
    on_message: Callable[[Transfer, GeneratedMessage], None] | None,
    standard: TypeTable,
) -> None:
    kind = transfer.id.kind
    cls, name = typed
    protocol = transfer.id.protocol
    key = (transfer.node, kind, transfer.id.data_type_id, protocol)
    stream = report.streams.get(key)
    if stream is None:
        other = standard.get((kind, transfer.id.data_type_id)) if protocol == "dronecan" else None
        name = name or (other[0] if other else "")
        stream = report.streams[key] = Stream(
            transfer.node, kind, transfer.id.data_type_id, name, 0, transfer.t, protocol=protocol
        )
    stream.see(transfer.t)
    if cls is None:
        return
    try:
        if protocol == "cyphal":  # padding past the last field reads as Cyphal's implicit extension: ignored
            message = cast(CyphalClass, cls).decode(transfer.payload)
        else:
            message = decode_transfer(cast(DronecanClass, cls), transfer)
    except ValueError as exc:  # the generated DecodeError
        stream.undecodable += 1
        note(
            Diagnostic(
                "can-decode",
                f"node {transfer.node}: {stream.name} transfer {transfer.transfer_id} does not decode: {exc}",
                transfer.t,
                transfer.frame,
                transfer.node,
                transfer.id.data_type_id,
            )
        )
        return
    if on_message is not None:
        on_message(transfer, message)
