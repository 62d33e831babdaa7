"""``battgen params``: battery failsafe parameter files.

    battgen params --from-devicetree FILE [--node PATH] [--cells N] [--low-soc 20] [--critical-soc 10]
                   [--ocv-table N] [--mah-thresholds] [--format param|qgc] [--out FILE]
    battgen params --check FILE [--cells N] [--chemistry lipo] [--vehicle rover|copter|plane|sub]

``--from-devicetree`` reads a .dts/.dtb, takes its simple-battery node and writes a parameter
file proposing BATT_CAPACITY and BATT_LOW_VOLT / BATT_CRT_VOLT, each with a comment saying where
the value came from. ``--check`` reads a parameter file (any layout ArduPilot, Mission Planner or
QGroundControl writes) and reports what ``battgen validate`` reports on it: the BATT_* values that
break their types and ranges, every battery's action codes for the vehicle (given, else detected,
else rover), and the plausibility warnings (codegen.apps.failsafe.checks).
Exit codes: 0 ok (warnings allowed), 1 the check found errors or the file holds no BATT*_ parameter
(``--allow-empty`` accepts that), 2 unreadable input or bad usage.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..apps.failsafe.checks import CELL_RANGES
from ..apps.failsafe.stream import batt_parameter_count, read_parameter_values
from ..apps.failsafe.vehicles import VEHICLES
from ..apps.parameters.check import check_parameter_file, check_proposals, propose_from_devicetree, render
from ..errors import BattgenError, place
from ..text.escape import line

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "params",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--from-devicetree", metavar="FILE", help=".dts/.dtsi/.dtb holding a simple-battery node")
    what.add_argument("--check", metavar="FILE", help="a .param (ArduPilot) or .params (QGroundControl) file")
    p.add_argument("--node", help="devicetree node path of the battery (default: the first simple-battery)")
    p.add_argument("--cells", type=int, help="cells in series (default: inferred from the design voltages)")
    p.add_argument("--low-soc", type=float, default=20.0, help="state of charge (%%) for BATT_LOW_VOLT (20)")
    p.add_argument("--critical-soc", type=float, default=10.0, help="state of charge (%%) for BATT_CRT_VOLT (10)")
    p.add_argument("--ocv-table", type=int, help="which ocv-capacity-table-N (default: the one nearest 20 degC)")
    p.add_argument("--mah-thresholds", action="store_true", help="also propose BATT_LOW_MAH / BATT_CRT_MAH")
    p.add_argument("--format", choices=("param", "qgc"), default="param", help="output file format (param)")
    p.add_argument("--out", "-o", help="write here instead of standard output")
    p.add_argument("--chemistry", choices=sorted(CELL_RANGES), default="lipo", help="for --check (lipo)")
    p.add_argument(
        "--vehicle", choices=sorted(VEHICLES), help="for --check: ArduPilot vehicle (default: detected, else rover)"
    )
    p.add_argument("--allow-empty", action="store_true", help="for --check: a file without BATT*_ is not an error")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.check:
        return _check(Path(args.check), args.cells, args.chemistry, args.vehicle, args.allow_empty)
    result, source = propose_from_devicetree(
        Path(args.from_devicetree),
        node=args.node,
        cells=args.cells,
        low_soc=args.low_soc,
        critical_soc=args.critical_soc,
        table=args.ocv_table,
        mah_thresholds=args.mah_thresholds,
    )
    text = render(result, source, args.format)
    for warning in result.warnings:  # what the node could not give: said, as well as written into the file
        print(line(f"battgen: warning: {source}: {warning}"), file=sys.stderr)
    for finding in check_proposals(result):
        print(line(f"battgen: {finding.severity}: {finding.message}"), file=sys.stderr)
    if args.out:
        try:
            Path(args.out).write_text(text, encoding="utf-8")
        except OSError as exc:
            raise BattgenError(f"{args.out}: cannot write: {exc.strerror or exc}") from None
    else:
        sys.stdout.write(text)
    return EXIT_OK


def _check(path: Path, cells: int | None, chemistry: str, vehicle: str | None, allow_empty: bool) -> int:
    display = path.as_posix()
    report = check_parameter_file(path, cells=cells, chemistry=chemistry, vehicle=vehicle)
    if report.unreadable is not None:
        print(line(f"battgen: {report.unreadable}"), file=sys.stderr)
        return EXIT_USAGE
    values = read_parameter_values(path)
    if not batt_parameter_count(values) and not allow_empty:
        print(
            line(
                f"{display}: no BATT*_ parameter in this file ({len(values)} parameters read): nothing to check "
                "(--allow-empty accepts that)"
            ),
            file=sys.stderr,
        )
        return EXIT_ERRORS
    for note in report.notes:
        print(line(f"{display}: {note}"), file=sys.stderr)
    for f in report.findings:
        print(line(f"{place(display, f.line)}: {f.severity}: {f.message}"))
    errors = sum(f.severity == "error" for f in report.findings)
    warnings = sum(f.severity == "warning" for f in report.findings)
    print(line(f"{display}: {errors} errors, {warnings} warnings"), file=sys.stderr)
    return EXIT_ERRORS if errors else EXIT_OK
