"""``battgen validate [--message NAME] FILE...``: check data files against a message's generated validator.

Inputs, by extension (or ``--input-format``): JSON (.json), JSON Lines (.jsonl/.ndjson), YAML
(.yaml/.yml), devicetree (.dts/.dtsi/.dtb), parameter files (ArduPilot .param/.parm, QGroundControl
.params), PX4 flight logs (.ulg), MAVLink telemetry logs (.tlog), raw MAVLink streams (.mav), and CAN
bus captures (candump .log, .asc, .blf, .trc; ArduPilot DataFlash .bin with CANF/CAFD records).

- Parameter files: one record per parameter set (per vehicle/component in a .params file) holding
  the message's parameters; a violation names its parameter's line. For params.BATT the failsafe
  cross-field checks (CRITICAL below LOW, thresholds below BATT_CAPACITY, plausible cell voltages,
  arming limits) are reported too.
- .ulg: every record of the message's topics (all multi_ids), located by topic, multi_id,
  timestamp and file offset. When the log's format for a topic differs from the schema's, the
  difference is printed once as a warning, the matching fields are checked, and the checks of the
  fields the log lacks or types differently are skipped (also said once).
- .tlog / .mav: every frame of the message, located by frame number, system/component id,
  sequence number and (tlog) time and offset; bad CRCs and garbage are one warning summary.

``--message`` may be omitted when the inputs imply a format with only one message in the schemas
(parameter files: params.BATT; MAVLink logs with the bundled schemas: mavlink.BATTERY_STATUS; CAN
captures: DroneCAN BatteryInfo, every battery node's records located by time, frame and node, with the
transport diagnostics -- toggle, CRC, missing start or end, transfer-id gaps, BatteryInfoAux order).

Prints one line per violation, ``file:line: message`` (``file: location: message`` for logs;
warnings marked, and not failing), notices about whole inputs and a summary on stderr; or with
``--format json`` one JSON document (each violation with its ``location``, each file with its
``notices``). Exit 0 valid, 1 violations, 2 unreadable input or unknown message.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..apps import validate as engine
from ..apps.failsafe.vehicles import VEHICLES
from ..apps.package import bundled_schemas
from ..apps.validate import Checker, Event, FileReport, Finding, exit_code, json_document, make_checker
from ..inputs.dispatch import KINDS
from ..inputs.records import Notice
from ..ir import Message


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _place(file: str, line: int) -> str:
    return f"{file}:{line}" if line > 0 else file  # a .dtb or a log has no lines


def finding_line(f: Finding) -> str:
    """A finding as printed: ``file:line: [warning: ][where: ]message``."""
    mark = "warning: " if f.severity == "warning" else ""
    where = f"{f.where}: " if f.where else ""
    return f"{_place(f.file, f.line)}: {mark}{where}{f.message}"


def print_event(event: Event) -> None:
    """Findings on stdout; warning and error notices, the stream summary of a log or capture and unreadable
    parts on stderr (other info notices: JSON only)."""
    if isinstance(event, Finding):
        print(finding_line(event))
    elif isinstance(event, Notice):
        if event.severity in ("warning", "error"):
            print(f"{event.file}: {event.severity}: {event.message}", file=sys.stderr)
        elif event.kind == "stream":  # what a log or capture held (frames, nodes): one line, worth seeing
            print(f"{event.file}: note: {event.message}", file=sys.stderr)
    else:
        print(f"{_place(event.file, event.line)}: {event.message}", file=sys.stderr)


def check_file(path: Path, message: Message, checker: Checker, *, echo: bool, kind: str | None = None) -> FileReport:
    """Check every record of one file; with ``echo`` print each finding as it is found (streaming)."""
    if echo:
        return engine.check_file(path, message, checker, kind=kind, keep_findings=False, on_event=print_event)
    return engine.check_file(path, message, checker, kind=kind)


def run(args: argparse.Namespace) -> int:
    schema_dir = Path(args.schemas) if args.schemas else bundled_schemas()
    kind = args.input_format
    message, checker = make_checker(schema_dir, args.message, args.files, kind, vehicle=args.vehicle)
    as_json = args.format == "json"
    reports = [check_file(Path(f), message, checker, echo=not as_json, kind=kind) for f in args.files]
    code = exit_code(reports)
    if as_json:
        json.dump(json_document(message, reports), sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        records = sum(r.records for r in reports)
        errors = sum(r.errors for r in reports)
        warnings = sum(r.warnings for r in reports)
        unreadable = sum(len(r.unreadable) for r in reports)
        summary = (
            f"{message.qualified_name}: {_count(records, 'record')} in {_count(len(reports), 'file')}, "
            f"{_count(errors, 'error')}, {_count(warnings, 'warning')}"
        )
        if unreadable:
            summary += f", {unreadable} unreadable"
        print(summary, file=sys.stderr)
    return code


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "validate",
        help="check data files, parameter files and flight/telemetry logs (.ulg, .tlog, .mav) against a message",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--message",
        metavar="NAME",
        help="qualified message name (uorb.BatteryStatus, mavlink.BATTERY_STATUS, params.BATT, ...) or an "
        "unambiguous short form; optional when the inputs' format has one message (parameter files: params.BATT; "
        "MAVLink logs: mavlink.BATTERY_STATUS)",
    )
    p.add_argument("--schemas", metavar="DIR", help="schema folder (default: the bundled schemas/)")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    p.add_argument(
        "--input-format",
        choices=KINDS,
        help="read every FILE as this format (default: from each extension; 'mavlink' is a raw MAVLink stream)",
    )
    p.add_argument(
        "--vehicle",
        choices=sorted(VEHICLES),
        help="ArduPilot vehicle of parameter files: what the BATT*_FS_*_ACT codes mean (default: detected, else rover)",
    )
    p.add_argument(
        "files",
        nargs="+",
        metavar="FILE",
        help=".json, .yaml/.yml, .jsonl/.ndjson, .dts/.dtsi, .dtb, .param/.parm/.params, .ulg, .tlog or .mav",
    )
    p.set_defaults(func=run)
