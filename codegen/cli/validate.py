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

Findings are grouped: one line per file, severity, rule and field (array indexes aside), the first
finding's ``file:line: message`` (``file: location: message`` for logs; warnings marked, and not
failing) and how many more records repeat it; notices about whole inputs and a summary on stderr.
``--format json`` gives one JSON document (every violation with its ``location``, each file with
its ``notices``), ``--format github`` GitHub Actions annotations (``::error file=...::``), and
``--format sarif`` a SARIF 2.1.0 log for code scanning.

A CI gate: ``--select`` / ``--ignore`` take selectors (``range/max_error``, ``range``, ``max_error``,
``cells-beyond-count-zero``, wildcards allowed), and ``--profile px4`` waives PX4's documented
deviations from its own .msg (each with its evidence, in codegen/apps/gate/profiles/px4.yaml); the
same settings may live under ``[tool.battgen]`` (``select``, ``ignore``, ``profile``) in the
nearest pyproject.toml. What is left out is counted in the summary (SARIF: suppressed results).
A file without records of the message is exit 1 (``--allow-empty`` accepts it).

Exit 0 valid, 1 violations or a file without records, 2 unreadable input or unknown message.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..apps.failsafe.vehicles import VEHICLES
from ..apps.gate import validate as engine
from ..apps.gate.formats import Group, Grouper, github_line, github_notice, sarif_document
from ..apps.gate.selection import KIND_FIRMWARE, Gate, Settings, check_selectors, describe, for_firmware, names_of
from ..apps.gate.validate import Checker, Event, FileReport, Finding, exit_code, is_empty, json_document, make_checker
from ..apps.schemas.package import bundled_package, bundled_schemas
from ..errors import BattgenError
from ..inputs.files.kinds import KINDS, file_kind
from ..inputs.records import Notice, Unreadable
from ..ir import Message
from ..text.escape import line
from .cyphal_options import add_cyphal_subject, check_subjects, subject_message
from .gate_options import add_gate_options, firmware_note, gate_settings


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
    """Warning and error notices, the stream summary of a log or capture and unreadable parts on
    stderr (other info notices: JSON only); findings are grouped and printed once their file is
    done (see :func:`print_groups`)."""
    if isinstance(event, Notice):
        if event.severity in ("warning", "error"):
            print(line(f"{event.file}: {event.severity}: {event.message}"), file=sys.stderr)
        elif event.kind == "stream":  # what a log or capture held (frames, nodes): one line, worth seeing
            print(line(f"{event.file}: note: {event.message}"), file=sys.stderr)
    elif isinstance(event, Unreadable):
        print(line(f"{_place(event.file, event.line)}: {event.message}"), file=sys.stderr)


def print_groups(grouper: Grouper, github: bool) -> None:
    """Each group of reported findings once: its first finding, with how often it repeats."""
    for group in grouper.groups():
        print(github_line(group) if github else line(finding_line(group.first) + group.repeats()))
    if grouper.overflow:
        print(f"... and {grouper.overflow} findings of further kinds (use --format json)")


def check_file(
    path: Path,
    message: Message,
    checker: Checker,
    grouper: Grouper | None = None,
    *,
    echo: bool,
    keep: bool | None = None,
    kind: str | None = None,
    gate: Gate | None = None,
    github: bool = False,
    subjects: Sequence[str] = (),
) -> FileReport:
    """Check every record of one file, grouping its findings as they come (memory bounded by the
    kinds of finding, not the records). With ``echo``, print notices as they come and the groups
    once the file is done (``github``: as workflow commands). ``keep`` (default: not ``echo``)
    keeps every finding in the report too (``--format json``)."""
    groups = grouper if grouper is not None else Grouper()

    def on_event(event: Event) -> None:
        if isinstance(event, Finding):
            groups.add(event)
        elif echo:
            print_event(event)

    keep_findings = not echo if keep is None else keep
    report = engine.check_file(
        path, message, checker, kind=kind, keep_findings=keep_findings, on_event=on_event, gate=gate, subjects=subjects
    )
    if echo:
        print_groups(groups, github)
    return report


def run(args: argparse.Namespace) -> int:
    schema_dir = Path(args.schemas) if args.schemas else bundled_schemas()
    kind = args.input_format
    chosen = gate_settings(args)
    message_name = args.message or subject_message(args.cyphal_subject, bundled_package().__name__)
    message, checker = make_checker(schema_dir, message_name, args.files, kind, vehicle=args.vehicle)
    check_subjects(args.cyphal_subject, checker.cls)
    check_selectors(chosen, names_of(message, checker.rules, checker.extra is not None))
    fmt = args.format
    text_like = fmt in ("text", "github")
    reports: list[FileReport] = []
    all_groups: list[Group] = []
    problems: list[tuple[str, str, str]] = []  # SARIF's tool notifications: (file, level, text)
    github = fmt == "github"
    in_force: list[Settings] = []
    for f in args.files:
        in_force.append(file_settings(chosen, Path(f), kind, echo=text_like))
        gate = Gate(in_force[-1], message.qualified_name)
        grouper = Grouper()
        report = check_file(
            Path(f),
            message,
            checker,
            grouper,
            echo=text_like,
            keep=fmt == "json",
            kind=kind,
            gate=gate,
            github=github,
            subjects=args.cyphal_subject,
        )
        reports.append(report)
        all_groups += grouper.groups() + grouper.groups(waived=True)
        problems += [(n.file, n.severity, f"{n.file}: {n.message}") for n in report.notices if n.severity == "warning"]
        problems += [(u.file, "error", f"{_place(u.file, u.line)}: {u.message}") for u in report.unreadable]
        if is_empty(report) and args.allow_empty:  # accepted, but a scan that saw nothing should say so
            problems.append((report.file, "note", f"{report.file}: no {message.qualified_name} records in this file"))
        if is_empty(report) and not args.allow_empty:
            text = f"no {message.qualified_name} records in this file (--allow-empty accepts that)"
            problems.append((report.file, "error", f"{report.file}: {text}"))
            if github:
                print(github_notice(report.file, text))
            elif text_like:
                print(line(f"{report.file}: {text}"), file=sys.stderr)
        if github:
            for u in report.unreadable:
                print(github_notice(u.file, u.message))
    code = exit_code(reports, allow_empty=args.allow_empty)
    if in_force and all(s == in_force[0] for s in in_force):  # one profile for all files: the summary names it
        chosen = in_force[0]
    if fmt == "json":
        json.dump(json_document(message, reports, allow_empty=args.allow_empty), sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    elif fmt == "sarif":
        doc = sarif_document(message.qualified_name, all_groups, problems, chosen, code, version())
        json.dump(doc, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(line(summary(message, reports, all_groups, chosen)), file=sys.stderr)
    return code


def file_settings(chosen: Settings, path: Path, kind: str | None, *, echo: bool) -> Settings:
    """The settings for one file: the profile of its firmware where none was asked for (said on stderr)."""
    try:
        found = kind or file_kind(path)
    except BattgenError:  # unreadable: the check says so
        return chosen
    own = for_firmware(chosen, KIND_FIRMWARE.get(found))
    note = firmware_note(path.as_posix(), own)
    if echo and note is not None:
        print(line(note), file=sys.stderr)
    return own


def version() -> str:
    import importlib.metadata  # for SARIF output only: it costs a run more than reading one record

    try:
        return importlib.metadata.version("battgen")
    except importlib.metadata.PackageNotFoundError:
        return "0"


def summary(message: Message, reports: list[FileReport], groups: list[Group], chosen: Settings) -> str:
    """The closing line: records, files, errors and warnings (with the lines that showed them),
    and what the selection left out."""
    records = sum(r.records for r in reports)
    errors = sum(r.errors for r in reports)
    warnings = sum(r.warnings for r in reports)
    waived = sum(r.waived for r in reports)
    shown = [g for g in groups if not g.first.waived]
    text = (
        f"{message.qualified_name}: {_count(records, 'record')} in {_count(len(reports), 'file')}, "
        f"{_count(errors, 'error')}, {_count(warnings, 'warning')}"
    )
    if errors or warnings:  # a reader's damage notice (a CAN transfer's bad CRC) is an error on a line of its own
        lines = len(shown) + sum(1 for r in reports for n in r.notices if n.severity == "error")
        text += f" (shown as {_count(lines, 'line')})"
    unreadable = sum(len(r.unreadable) for r in reports)
    if unreadable:
        text += f", {unreadable} unreadable"
    empty = sum(1 for r in reports if is_empty(r))
    if empty:
        text += f", {empty} without records"
    if waived:
        left_out = sorted({": ".join(g.first.waived.split(": ")[:2]) for g in groups if g.first.waived})
        text += f"; {_count(waived, 'finding')} left out: " + "; ".join(left_out)
    used = list(describe(chosen))
    if used:
        text += f" [{', '.join(used)}{' from ' + chosen.origin if chosen.origin else ''}]"
    return text


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "validate",
        help=summary,
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
    p.add_argument(
        "--format",
        choices=("text", "json", "github", "sarif"),
        default="text",
        help="text (default), json, github (workflow-command annotations) or sarif (SARIF 2.1.0, code scanning)",
    )
    add_gate_options(p)
    p.add_argument("--allow-empty", action="store_true", help="a file without records is not an error")
    p.add_argument(
        "--input-format",
        choices=KINDS,
        help="read every FILE as this format (default: from each extension; 'mavlink' is a raw MAVLink stream)",
    )
    add_cyphal_subject(p)
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
