"""The engine of ``battgen params``: battery failsafe parameter files, proposed and checked.

:func:`propose_from_devicetree` reads a devicetree battery (a ``simple-battery`` node) and proposes
the BATT_* parameters (:mod:`.batt_proposal`); :func:`render` writes them as an ArduPilot .param
or a QGroundControl .params file. :func:`check_parameter_file` reads a parameter file and checks each
parameter set against the generated parameter model (types, ranges) and the failsafe's
cross-field rules (:mod:`.failsafe.checks`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, cast

from ...errors import BattgenError, place
from ...frontends import devicetree as devicetree_schemas
from ...inputs import devicetree
from ...inputs.model import MessageClass
from ...inputs.parameters import files as parameter_files
from ...ir import Message
from ..failsafe.checks import Finding, check_settings
from ..failsafe.vehicles import detect_vehicle
from ..gate.validate import check_file, failsafe_check, make_checker
from ..schemas.package import bundled_package, bundled_schemas, package_module
from .proposal import Result, propose

BATTERY_COMPATIBLE = "simple-battery"
BATTERY_MESSAGE = "devicetree.power.supply.battery"
BATT_MESSAGE_NAME = "params.BATT"


def _battery_message() -> Message:
    schema = devicetree_schemas.parse_dir(bundled_schemas() / "devicetree")
    return schema.message(BATTERY_MESSAGE)


def _batt_params() -> MessageClass:
    """The bundled package's class of the BATT_* parameters (params.BATT)."""
    return cast(MessageClass, package_module(bundled_package(), "params").BattParams)


def propose_from_devicetree(
    path: Path,
    *,
    node: str | None = None,
    cells: int | None = None,
    low_soc: float = 20.0,
    critical_soc: float = 10.0,
    table: int | None = None,
    mah_thresholds: bool = False,
) -> tuple[Result, str]:
    """The proposals from the first simple-battery node of a .dts/.dtb (or the one at ``node``,
    a path or a label), and the words naming where they came from."""
    nodes = devicetree.read_nodes(path)
    batteries = devicetree.find_compatible(nodes, BATTERY_COMPATIBLE)
    if node:
        batteries = [n for n in batteries if n.path == node or node in n.labels]
    if not batteries:
        wanted = f" at {node}" if node else ""
        raise BattgenError(f'{path}: expected a compatible = "{BATTERY_COMPATIBLE}" node{wanted}')
    battery = batteries[0]
    props = devicetree.node_to_model_dict(battery, _battery_message())
    file = battery.file or path.as_posix()
    lines = {name: f"{Path(v.file or file).name}:{v.line}" for name, v in battery.properties.items() if v.line}
    where = f"{file}:{battery.line} ({battery.path})"
    result = propose(
        props,
        where=where,
        lines=lines,
        cells=cells,
        low_soc=low_soc,
        critical_soc=critical_soc,
        table=table,
        mah_thresholds=mah_thresholds,
    )
    return result, f"{Path(file).name}:{battery.line} ({battery.path}, {BATTERY_COMPATIBLE})"


def check_proposals(result: Result) -> list[Finding]:
    """The failsafe's cross-field findings about the proposed parameters (with the cell count and
    chemistry the proposal assumed)."""
    cells = result.cells or None  # 0: not known (a node without design voltages)
    return check_settings({p.name: p.value for p in result.proposals}, cells=cells, chemistry=result.chemistry)


def render(result: Result, source: str, fmt: str) -> str:
    """The proposals as a parameter file: ``param`` (ArduPilot) or ``qgc`` (QGroundControl)."""
    header = [f"Battery failsafe parameters proposed by battgen from {source}", *result.notes, *result.warnings]
    if fmt == "qgc":
        types = {f.name: f.metadata["type"] for f in dataclasses.fields(cast(Any, _batt_params()))}
        items = [
            (p.name, p.value, parameter_files.TYPE_OF.get(types.get(p.name, "float32"), 9)) for p in result.proposals
        ]
        header += [f"{p.name}: {p.comment}" for p in result.proposals]
        return parameter_files.write_qgc(items, header=header)
    return parameter_files.write_param([(p.name, p.value, p.comment) for p in result.proposals], header=header)


@dataclass(frozen=True)
class ParameterFinding:
    line: int
    severity: str  # "error" or "warning"
    message: str


@dataclass(frozen=True)
class ParameterReport:
    findings: list[ParameterFinding]
    notes: list[str]  # what to know about the whole file: repeated parameters, the vehicle
    unreadable: str | None  # why the file could not be read (then no findings)


def check_parameter_file(
    path: Path, *, cells: int | None = None, chemistry: str = "lipo", vehicle: str | None = None
) -> ParameterReport:
    """Every problem of each parameter set of a parameter file, found by the very engine ``battgen
    validate`` runs (the generated model's types and ranges, then the failsafe checks of every
    battery with the vehicle's action codes), so the two commands agree on every file."""
    _, checker = make_checker(bundled_schemas(), BATT_MESSAGE_NAME, vehicle=vehicle)
    checker.extra = partial(failsafe_check, cells=cells, chemistry=chemistry)
    report = check_file(path, checker.message, checker, kind="param")
    notes = [n.message for n in report.notices]
    try:
        values: dict[str, object] = {}
        for _, group in parameter_files.read_parameter_file(path):
            values.update(group)
        notes.append(f"vehicle {detect_vehicle(values, vehicle).how}")
    except BattgenError:
        pass
    findings = [ParameterFinding(f.line, f.severity, f.message) for f in report.findings]
    first = report.unreadable[0] if report.unreadable else None
    unreadable = None if first is None else f"{place(first.file, first.line)}: {first.message}"
    return ParameterReport(findings, notes, unreadable)
