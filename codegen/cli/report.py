"""``battgen report LOG... [-o report.html] [--format html|png]``: a flight's battery at a glance.

Reads any log or capture battgen reads (PX4 ``.ulg``, MAVLink ``.tlog``, CAN captures -- a Cyphal/CAN capture's UDRAL
batteries with ``--cyphal-subject ID=TYPE`` as ``export`` reads them --, JSON Lines of a bundled message with
``--message``) and writes one self-contained HTML page (plotly embedded, opens offline): per battery
instance the time plots of pack voltage, current, power, state of charge, temperature and every cell with the
imbalance, the failsafe replay marked on the time axis (``--params`` with the BATT_* values, ``--vehicle``), the
validation findings grouped by rule with links to their time, and the figures (charge and energy used, average
and peak power, minimum pack and cell voltage, time under each threshold, voltage sag per amp and an internal
resistance estimate from load steps). Each input opens with what the log says about itself: vehicle type, firmware,
hardware, start (UTC where known), duration, armed spans (shaded on the plots), the battery parameters it recorded,
and the firmware's own warning levels (PX4 ``battery_status.warning``, MAVLink ``charge_state``) marked on the time
axis; thresholds come from the log's own parameters unless ``--params`` gives others, and the page says which.
Findings are gated as ``validate`` gates them: ``--select``, ``--ignore``, ``--profile`` and ``[tool.battgen]``,
the profile following the log's firmware unless given (a PX4 log: ``px4``); an unknown name is exit 2.
Several inputs give a fleet page: a row per flight and battery with its date and firmware, and trends per pack
serial over the flights' dates. ``--format png`` writes one static image per battery into the ``-o`` folder instead;
``--format json`` the figures, per input and battery (the page's and the flight's in SI), to ``-o`` or stdout.
Exit 0 when written, 1 when the inputs hold no battery record (``--allow-empty``: 0, nothing written), 2 when an
input cannot be read or the output cannot be written.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..apps.failsafe.vehicles import VEHICLES
from ..apps.gate.selection import unknown_name
from ..apps.report.as_json import report_json
from ..apps.report.build import collect, html, pngs
from ..apps.schemas.package import bundled_schemas
from ..errors import BattgenError, missing_file
from ..text.escape import line
from .cyphal_options import add_cyphal_subject, check_bundled_subjects
from .gate_options import add_gate_options, firmware_note, gate_settings

EXIT_OK, EXIT_EMPTY = 0, 1


def run(args: argparse.Namespace) -> int:
    schema_dir = Path(args.schemas) if args.schemas else bundled_schemas()
    paths = [Path(p) for p in args.logs]
    for p in paths:
        if not p.is_file():
            raise missing_file(str(p))
    check_bundled_subjects(args.cyphal_subject)  # a wrong ID=TYPE pair said once, before any input is read
    if args.vehicle is not None and args.vehicle not in VEHICLES:
        raise unknown_name("vehicle", args.vehicle, VEHICLES)
    report = collect(
        paths,
        schema_dir,
        message=args.message,
        params=Path(args.params) if args.params else None,
        vehicle=args.vehicle,
        gate=gate_settings(args),
        subjects=args.cyphal_subject,
    )
    for item in report.inputs:  # the profile the log's firmware chose, as validate says it
        note = firmware_note(item.source, item.gate) if item.gate is not None else None
        if note is not None:
            print(line(note), file=sys.stderr)
    if not any(i.batteries for i in report.inputs):  # readable, but nothing to draw: exit 1 as the README says
        names = ", ".join(str(p) for p in paths)
        if args.allow_empty:
            print(line(f"{names}: no battery records: nothing to report, nothing written"), file=sys.stderr)
            return EXIT_OK
        print(line(f"{names}: expected battery records, found none (--allow-empty accepts that)"), file=sys.stderr)
        return EXIT_EMPTY
    if args.format == "png":
        folder = Path(args.output or "report")
        if folder.exists() and not folder.is_dir():
            raise BattgenError(f"{folder}: --format png writes a folder of images, and this is a file")
        for path in pngs(report, folder):
            print(line(f"wrote {path}"))
        return EXIT_OK
    if args.format == "json":
        document = json.dumps(report_json(report), indent=2, ensure_ascii=True) + "\n"
        if args.output is None or args.output == "-":
            sys.stdout.write(document)
            return EXIT_OK
        _write(Path(args.output), document)
        print(line(f"wrote {args.output}"))
        return EXIT_OK
    out = Path(args.output or "report.html")
    text = html(report, title=args.title or "")
    _write(out, text)
    batteries = sum(len(i.batteries) for i in report.inputs)
    print(
        line(f"wrote {out} ({len(report.inputs)} input(s), {batteries} battery instance(s), {len(text) // 1024} KiB)")
    )
    return EXIT_OK


def _write(out: Path, text: str) -> None:
    if out.is_dir():
        raise BattgenError(f"{out}: is a folder; give the output's file name")
    if not out.parent.is_dir():
        raise BattgenError(f"{out.parent}: no such folder for the report")
    try:
        out.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise BattgenError(f"{out}: cannot write: {exc.strerror or exc}") from None


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "report",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("logs", nargs="+", metavar="LOG", help=".ulg, .tlog, CAN captures, or data files with --message")
    p.add_argument(
        "-o",
        "--output",
        metavar="PATH",
        help="the HTML file (default report.html); with --format png the folder of images (default report/); with "
        "--format json the file (default: stdout)",
    )
    p.add_argument("--format", choices=("html", "png", "json"), default="html", help="output (default: html)")
    p.add_argument("--message", metavar="NAME", help="the message of data-file inputs (default by log kind)")
    add_cyphal_subject(p)
    p.add_argument("--schemas", metavar="DIR", help="schema folder (default: the bundled schemas/)")
    p.add_argument(
        "--params",
        metavar="FILE",
        help="parameter file whose values replace the log's own for the thresholds and the failsafe replay "
        "(default: the log's own parameters)",
    )
    p.add_argument("--vehicle", metavar="NAME", help=f"vehicle of the failsafe ({', '.join(sorted(VEHICLES))})")
    add_gate_options(p)
    p.add_argument("--title", metavar="TEXT", help="the page's title")
    p.add_argument("--allow-empty", action="store_true", help="inputs without battery records are not an error")
    p.set_defaults(func=run)
