"""Checks of a parameter set's battery failsafe settings, every battery (BATT_, BATT2_ .. BATTG_).

Errors are values ArduPilot cannot act on:
- an action code the vehicle has no meaning for (``@Values{Vehicle}`` of FS_LOW_ACT / FS_CRT_ACT in
  ``AP_BattMonitor_Params.cpp``), or a code that is no integer;
- ``FS_VOLTSRC`` other than 0 (raw) or 1 (sag compensated);
- ``LOW_TIMER`` outside its declared ``@Range 0 120`` (battery 1's ranges are the schema's, so the
  generated validator reports them; here the other batteries').

Warnings are plausibility, which ArduPilot itself does not refuse in flight:
- a negative threshold (ArduPilot treats anything not above 0 as disabled);
- CRITICAL not below LOW (``AP_BattMonitor_Backend::arming_checks`` refuses to arm when LOW is
  below CRITICAL);
- capacity thresholds without BATT_CAPACITY, or not below it (they trigger at once);
- ``LOW_TIMER`` = 0 with voltage thresholds set: it disables both voltage failsafes;
- per-cell voltages: with the cell count known, each threshold divided by it must lie in the
  chemistry's plausible range (LiPo 3.0..4.35 V); without it, some cell count from 1 to 14 must put
  every threshold in that range;
- arming limits at or below the LOW thresholds (the failsafe would trigger right after arming).

Each finding names the parameter it is about, so a caller can report that parameter's line.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ...inputs.parameters import files as parameter_files
from .settings import instances, prefix
from .vehicles import DEFAULT_VEHICLE, VEHICLES, Vehicle

# plausible per-cell voltage under load, empty to full, by chemistry
CELL_RANGES: dict[str, tuple[float, float]] = {
    "lipo": (3.0, 4.35),
    "lion": (2.8, 4.2),
    "lihv": (3.0, 4.45),
    "life": (2.5, 3.65),
    "limn": (2.8, 4.2),
    "nimh": (0.9, 1.5),
    "nicd": (0.9, 1.5),
}
MAX_CELLS = 14  # uORB battery_status carries 14 cell voltages
VOLTAGES = ("LOW_VOLT", "CRT_VOLT", "ARM_VOLT")
NONNEGATIVE: tuple[str, ...] = ("BATT_CAPACITY", "BATT_LOW_VOLT", "BATT_CRT_VOLT", "BATT_LOW_MAH", "BATT_CRT_MAH")
NONNEGATIVE += ("BATT_ARM_VOLT", "BATT_ARM_MAH", "BATT_LOW_TIMER")
_THRESHOLDS = ("CAPACITY", "LOW_VOLT", "CRT_VOLT", "LOW_MAH", "CRT_MAH", "ARM_VOLT", "ARM_MAH")
LOW_TIMER_RANGE = (0, 120)


@dataclass(frozen=True)
class Finding:
    severity: str  # "error" or "warning"
    param: str
    message: str


def _num(values: Mapping[str, object], name: str, default: float = 0.0) -> float:
    value = values.get(name, default)
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else default


def check_settings(
    values: Mapping[str, object],
    *,
    cells: int | None = None,
    chemistry: str = "lipo",
    vehicle: Vehicle | None = None,
) -> list[Finding]:
    """Every problem of the failsafe settings of each battery in a parameter set (absent parameters
    at ArduPilot's defaults). ``vehicle`` gives the action codes their meaning (default: rover)."""
    if chemistry not in CELL_RANGES:
        raise ValueError(f"expected a chemistry among {', '.join(CELL_RANGES)}, got {chemistry!r}")
    if cells is not None and cells < 1:
        raise ValueError(f"expected a cell count of at least 1, got {cells}")
    vehicle = vehicle or VEHICLES[DEFAULT_VEHICLE]
    out: list[Finding] = []
    for instance in instances(values):
        out.extend(_check_battery(values, instance, vehicle, cells, chemistry))
    return out


def _check_battery(
    values: Mapping[str, object], instance: int, vehicle: Vehicle, cells: int | None, chemistry: str
) -> list[Finding]:
    head = prefix(instance)
    out: list[Finding] = []
    v = {f: _num(values, head + f) for f in _THRESHOLDS}
    if head + "LOW_VOLT" not in values:
        v["LOW_VOLT"] = vehicle.default_low_volt
    if head + "CAPACITY" not in values:
        v["CAPACITY"] = 3300.0
    timer = _num(values, head + "LOW_TIMER", 10.0)
    for field in ("FS_LOW_ACT", "FS_CRT_ACT"):
        name, level = head + field, "critical" if field == "FS_CRT_ACT" else "low"
        if name not in values:
            continue
        code, table = values[name], vehicle.actions(level)
        if isinstance(code, bool) or not isinstance(code, int | float) or not float(code).is_integer():
            out.append(Finding("error", name, f"{name} is {code!r}: expected an integer action code"))
        elif int(code) not in table:
            known = ", ".join(f"{c} {label}" for c, label in table.items())
            out.append(Finding("error", name, f"{name} = {int(code)} is no {vehicle.name} action (expected {known})"))
    src = head + "FS_VOLTSRC"
    if src in values and _num(values, src, -1) not in (0, 1):
        out.append(Finding("error", src, f"{src} = {values[src]!r}: expected 0 (raw voltage) or 1 (sag compensated)"))
    lo, hi = LOW_TIMER_RANGE
    if instance != 1 and not lo <= timer <= hi:
        out.append(Finding("error", head + "LOW_TIMER", f"{head}LOW_TIMER is {timer:g}: expected {lo} to {hi} s"))
    for field in _THRESHOLDS:
        if v[field] < 0:
            name = head + field
            out.append(
                Finding("warning", name, f"{name} is {v[field]:g}: ArduPilot treats a negative value as 0 (off)")
            )
    low_v, crt_v, low_m, crt_m, cap = v["LOW_VOLT"], v["CRT_VOLT"], v["LOW_MAH"], v["CRT_MAH"], v["CAPACITY"]
    if low_v > 0 and crt_v > 0 and crt_v >= low_v:
        text = f"{head}CRT_VOLT ({crt_v:g} V) is not below {head}LOW_VOLT ({low_v:g} V)"
        out.append(Finding("warning", head + "CRT_VOLT", text))
    if low_m > 0 and crt_m > 0 and crt_m >= low_m:
        text = f"{head}CRT_MAH ({crt_m:g} mAh) is not below {head}LOW_MAH ({low_m:g} mAh)"
        out.append(Finding("warning", head + "CRT_MAH", text))
    for field in ("LOW_MAH", "CRT_MAH"):
        name = head + field
        if v[field] > 0 and cap <= 0:
            text = f"{name} needs {head}CAPACITY (the remaining charge is capacity - used)"
            out.append(Finding("warning", name, text))
        elif v[field] > 0 and v[field] >= cap:
            text = f"{name} ({v[field]:g} mAh) is not below {head}CAPACITY ({cap:g} mAh): it triggers at once"
            out.append(Finding("warning", name, text))
    if timer == 0 and (low_v > 0 or crt_v > 0):
        text = f"{head}LOW_TIMER = 0 disables the LOW and CRITICAL voltage failsafes"
        out.append(Finding("warning", head + "LOW_TIMER", text))
    out.extend(_per_cell(head, v, cells, chemistry))
    arm_v, arm_m = v["ARM_VOLT"], v["ARM_MAH"]
    if arm_v > 0 and low_v > 0 and arm_v <= low_v:
        text = f"{head}ARM_VOLT ({arm_v:g} V) is not above {head}LOW_VOLT ({low_v:g} V)"
        out.append(Finding("warning", head + "ARM_VOLT", text))
    if arm_m > 0 and low_m > 0 and arm_m <= low_m:
        text = f"{head}ARM_MAH ({arm_m:g} mAh) is not above {head}LOW_MAH ({low_m:g} mAh)"
        out.append(Finding("warning", head + "ARM_MAH", text))
    return out


def _per_cell(head: str, v: Mapping[str, float], cells: int | None, chemistry: str) -> list[Finding]:
    lo, hi = CELL_RANGES[chemistry]
    set_ = [(head + n, v[n]) for n in VOLTAGES if v[n] > 0]
    if not set_:
        return []
    if cells is not None:
        return [
            Finding(
                "warning",
                name,
                f"{name} ({value:g} V) is {value / cells:.2f} V per cell for {cells} cells, "
                f"outside {lo:g}..{hi:g} V for {chemistry}",
            )
            for name, value in set_
            if not lo <= value / cells <= hi
        ]
    if any(all(lo <= value / n <= hi for _, value in set_) for n in range(1, MAX_CELLS + 1)):
        return []
    names = ", ".join(f"{name} {value:g} V" for name, value in set_)
    return [
        Finding(
            "warning",
            set_[0][0],
            f"no cell count from 1 to {MAX_CELLS} puts {names} within {lo:g}..{hi:g} V per cell ({chemistry})",
        )
    ]


def check_file(
    path: Path, *, cells: int | None = None, chemistry: str = "lipo", vehicle: Vehicle | None = None
) -> list[tuple[str, int, Finding]]:
    """The findings of a parameter file as (file, line of the parameter, finding)."""
    display = path.as_posix()
    entries = parameter_files.load(path, display)
    lines = {e.name: e.line for e in entries}
    out: list[tuple[str, int, Finding]] = []
    for first, values in parameter_files.read_parameter_file(path):
        for finding in check_settings(values, cells=cells, chemistry=chemistry, vehicle=vehicle):
            out.append((display, lines.get(finding.param, first), finding))
    return out
