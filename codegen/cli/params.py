"""``battgen params``: battery failsafe parameter files.

    battgen params --from-devicetree FILE [--node PATH] [--cells N] [--low-soc 20] [--critical-soc 10]
                   [--ocv-table N] [--mah-thresholds] [--format param|qgc] [--out FILE]
    battgen params --check FILE [--cells N] [--chemistry lipo]

``--from-devicetree`` reads a .dts/.dtb, takes its simple-battery node and writes a parameter
file proposing BATT_CAPACITY and BATT_LOW_VOLT / BATT_CRT_VOLT, each with a comment saying where
the value came from. ``--check`` reads a .param / .params file and reports the BATT_* values
that break their ranges or the cross-field rules (codegen.apps.failsafe.checks).
Exit codes: 0 ok (warnings allowed), 1 the check found errors, 2 unreadable input or bad usage.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

from ..apps.failsafe.checks import CELL_RANGES, check_params
from ..apps.param_proposal import Result, propose
from ..errors import BattgenError
from ..inputs import paramfile

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2
BATTERY_COMPATIBLE = "simple-battery"


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "params",
        help="propose battery failsafe parameters from a devicetree battery, or check a parameter file",
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
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.check:
        return _check(Path(args.check), args.cells, args.chemistry)
    result, source = from_devicetree(Path(args.from_devicetree), args)
    text = render(result, source, args.format)
    for finding in check_params(
        {p.name: p.value for p in result.proposals}, cells=result.cells, chemistry=result.chemistry
    ):
        print(f"battgen: {finding.severity}: {finding.message}", file=sys.stderr)
    if args.out:
        try:
            Path(args.out).write_text(text, encoding="utf-8")
        except OSError as exc:
            raise BattgenError(f"{args.out}: cannot write: {exc.strerror or exc}") from None
    else:
        sys.stdout.write(text)
    return EXIT_OK


def _battery_message() -> Any:
    from ..frontends import devicetree
    from .main import project_root

    schema = devicetree.parse_dir(project_root() / "schemas" / "devicetree")
    return schema.message("devicetree.power.supply.battery")


def from_devicetree(path: Path, args: argparse.Namespace) -> tuple[Result, str]:
    from ..inputs import devicetree as dts

    nodes = dts.read_nodes(path)
    batteries = dts.find_compatible(nodes, BATTERY_COMPATIBLE)
    if args.node:
        batteries = [n for n in batteries if n.path == args.node or args.node in n.labels]
    if not batteries:
        wanted = f" at {args.node}" if args.node else ""
        raise BattgenError(f'{path}: expected a compatible = "{BATTERY_COMPATIBLE}" node{wanted}')
    node = batteries[0]
    props = dts.node_to_model_dict(node, _battery_message())
    file = node.file or path.as_posix()
    lines = {name: f"{Path(v.file or file).name}:{v.line}" for name, v in node.properties.items() if v.line}
    where = f"{file}:{node.line} ({node.path})"
    result = propose(
        props,
        where=where,
        lines=lines,
        cells=args.cells,
        low_soc=args.low_soc,
        critical_soc=args.critical_soc,
        table=args.ocv_table,
        mah_thresholds=args.mah_thresholds,
    )
    return result, f"{Path(file).name}:{node.line} ({node.path}, {BATTERY_COMPATIBLE})"


def render(result: Result, source: str, fmt: str) -> str:
    header = [f"Battery failsafe parameters proposed by battgen from {source}", *result.notes]
    if fmt == "qgc":
        from generated.params import BattParams

        types = {f.name: f.metadata["type"] for f in dataclasses.fields(BattParams)}
        items = [(p.name, p.value, paramfile.TYPE_OF.get(types.get(p.name, "float32"), 9)) for p in result.proposals]
        header += [f"{p.name}: {p.comment}" for p in result.proposals]
        return paramfile.write_qgc(items, header=header)
    return paramfile.write_param([(p.name, p.value, p.comment) for p in result.proposals], header=header)


def _check(path: Path, cells: int | None, chemistry: str) -> int:
    from generated._meta import DataError
    from generated.params import BattParams

    display = path.as_posix()
    entries = paramfile.load(path, display)
    lines = {e.name: e.line for e in entries}
    errors = warnings = 0
    for first, values in paramfile.read_param_file(path):
        batt = paramfile.select(values, BattParams)
        try:
            model = BattParams.from_dict(batt)
        except DataError as exc:
            print(f"{display}:{lines.get(exc.path, first)}: error: {exc}")
            errors += 1
            continue
        for f in dataclasses.fields(BattParams):
            value, lo, hi = getattr(model, f.name), f.metadata["minimum"], f.metadata["maximum"]
            if (lo is not None and value < lo) or (hi is not None and value > hi):
                print(f"{display}:{lines.get(f.name, first)}: error: {f.name} is {value:g}: expected {lo:g} to {hi:g}")
                errors += 1
        for finding in check_params(model.to_dict(), cells=cells, chemistry=chemistry):
            print(f"{display}:{lines.get(finding.param, first)}: {finding.severity}: {finding.message}")
            errors += finding.severity == "error"
            warnings += finding.severity == "warning"
    print(f"{display}: {errors} errors, {warnings} warnings", file=sys.stderr)
    return EXIT_ERRORS if errors else EXIT_OK
