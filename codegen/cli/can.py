"""``battgen can CAPTURE... | --bus IFACE:CHANNEL``: what a DroneCAN or Cyphal/CAN bus carried, and what was wrong on
the wire.

Reads CAN captures (candump ``.log``, ``.asc``, ``.blf``, ``.trc``, python-can ``.csv`` with ``--input-format can``,
each also ``.gz`` or ``.xz``; ArduPilot DataFlash ``.bin`` logs with CANF/CAFD records) or a live python-can bus
(``socketcan:can0``, ``slcan:/dev/ttyACM0``, ``virtual:NAME``; until Ctrl-C or ``--duration``), reassembles every
DroneCAN transfer and prints, per capture: each node's data types with counts and rates, then the transport
problems (toggle errors, CRC mismatches and the signature they point to, missing start or end frames, transfer-id
gaps, BatteryInfoAux sent out of order, transfers that do not decode), the first few of each kind with the frame's
time and position, and counts. ``--records`` also prints every decoded message as a JSON line on stdout.
Cyphal/CAN (``--transport cyphal``, or ``mixed`` beside DroneCAN, told apart by the start frame's toggle bit):
each ``--cyphal-subject ID=TYPE`` names the type a subject carries, whose transfers are then decoded; ``--schemas
DIR`` reads a Cyphal DSDL tree, whose types with a fixed port id (the Heartbeat on 7509, ...) are named and decoded.
``--format json`` prints one JSON document instead. Exit 0 clean, 1 transport errors, 2 unreadable input.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..apps.can.capture import CaptureReport, scan
from ..apps.can.known_types import cyphal_types, shipped_tree, standard_types
from ..apps.schemas.package import bundled_package
from ..errors import BattgenError, LocatedError, missing_file
from ..inputs.can.captures import read_bus
from ..inputs.can.cyphal_ports import cyphal_classes, subject_table
from ..inputs.can.cyphal_reassembly import TRANSPORTS
from ..inputs.can.reassembly import Frame, Transfer
from ..inputs.can.records import frames_of, registry
from ..inputs.model import GeneratedMessage
from ..ir.numbers import to_json_data
from ..text.escape import line
from .cyphal_options import add_cyphal_subject

EXIT_OK, EXIT_ERRORS, EXIT_UNREADABLE = 0, 1, 2


def _print_record(transfer: Transfer, message: GeneratedMessage) -> None:
    data: dict[str, object] = {
        "t": transfer.t,
        "node": transfer.node,
        "frame": transfer.frame,
        "type": type(message).__name__,
    }
    if transfer.id.protocol == "cyphal":
        data.update(protocol="cyphal", subject=transfer.id.data_type_id)
    data["message"] = to_json_data(message.to_dict())
    print(json.dumps(data, allow_nan=False))


def _text(report: CaptureReport) -> None:
    print(line(f"{report.source}: {report.frames} frames, {report.transfers} transfers in {report.duration:.3f} s"))
    for (node, kind, type_id, _), s in sorted(report.streams.items()):
        name = s.name or "(unknown type)"
        bad = f", {s.undecodable} undecodable" if s.undecodable else ""
        print(line(f"  node {node:3d}  {kind:8s} {type_id:5d} {name:45s} {s.count:7d} x {s.rate:8.2f} Hz{bad}"))
    for d in report.problems:
        print(line(f"{report.source}: t={d.t:.6f} s, frame {d.frame}: {d.severity}: {d.message} [{d.code}]"))
    for code, n in sorted(report.counts.items()):
        print(line(f"{report.source}: {n} x {code}"), file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    package = bundled_package().__name__
    known = registry(package)
    classes = cyphal_classes(package)
    if args.schemas:  # a user's Cyphal tree: its fixed-port types named and decoded (the bundled ones win a name)
        classes = {**cyphal_types(Path(args.schemas)), **classes}
    subjects = subject_table(args.cyphal_subject, classes)
    transport = args.transport or ("mixed" if args.cyphal_subject or args.schemas else "dronecan")
    # every standard type is CRC-checked and named, not only the generated package's battery types
    standard = standard_types(Path(args.dsdl) if args.dsdl else shipped_tree())
    on_message = _print_record if args.records else None
    sources: list[tuple[str, Iterator[Frame]]] = []
    if args.bus:
        sources.append((args.bus, read_bus(args.bus, duration=args.duration)))
    for name in args.files:
        path = Path(name)
        if not path.is_file():
            raise missing_file(name)
        sources.append((name, frames_of(path, name, args.input_format)))
    if not sources:
        raise BattgenError("give a capture file or --bus IFACE:CHANNEL")
    reports: list[CaptureReport] = []
    code = EXIT_OK
    for name, frames in sources:
        try:
            report = scan(
                frames, name, known, on_message=on_message, standard=standard, transport=transport, subjects=subjects
            )
        except KeyboardInterrupt:  # a live bus stopped by the user: the report of what was seen is still wanted
            print(line(f"{name}: stopped"), file=sys.stderr)
            continue
        except LocatedError as exc:
            where = f"{exc.file}:{exc.line}" if exc.line else exc.file  # line 0: the whole capture
            print(line(f"{where}: {exc.message}"), file=sys.stderr)
            code = EXIT_UNREADABLE
            continue
        reports.append(report)
        if report.frames == 0:
            print(line(f"{name}: no CAN frames"), file=sys.stderr)
            code = max(code, EXIT_ERRORS)
        if report.errors:
            code = max(code, EXIT_ERRORS)
        if args.format == "text":
            _text(report)
    if args.format == "json":
        json.dump({"captures": [r.to_dict() for r in reports], "exit_code": code}, sys.stdout, indent=2)
        sys.stdout.write("\n")
    return code


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "can",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("files", nargs="*", metavar="CAPTURE", help="capture files (.log .asc .blf .trc, .bin DataFlash)")
    p.add_argument("--bus", metavar="IFACE:CHANNEL", help="read a live python-can bus instead (socketcan:can0, ...)")
    p.add_argument("--duration", type=float, metavar="S", help="with --bus: stop after S seconds (default: Ctrl-C)")
    p.add_argument(
        "--input-format",
        choices=("can", "dataflash"),
        help="read every CAPTURE as this: 'can' a python-can log (a .csv too), 'dataflash' a log's CANF/CAFD records",
    )
    p.add_argument(
        "--dsdl",
        metavar="DIR",
        help="a DroneCAN DSDL root (a copy of dronecan/DSDL) whose types are named and CRC-checked "
        "(default: the tree the dronecan package ships, where installed)",
    )
    p.add_argument(
        "--transport",
        choices=TRANSPORTS,
        help="what the bus carries: DroneCAN (v0), Cyphal/CAN (v1), or both, told apart by the start frame's toggle "
        "bit (default: dronecan, mixed with --cyphal-subject)",
    )
    add_cyphal_subject(p)
    p.add_argument(
        "--schemas",
        metavar="DIR",
        help="a Cyphal DSDL tree (a copy of public_regulated_data_types: uavcan/, reg/) whose types with a fixed "
        "port id (uavcan.node.Heartbeat.1.0 on 7509, ...) are named and decoded; implies --transport mixed",
    )
    p.add_argument("--records", action="store_true", help="also print every decoded message as a JSON line")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    p.set_defaults(func=run)
