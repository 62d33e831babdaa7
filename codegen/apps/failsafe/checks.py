"""Cross-field checks of the BATT_* failsafe parameters (the seed's rules), beyond one field's range.

- A threshold of 0 is disabled; a negative one is an error.
- CRITICAL must be below LOW, for the voltage and for the capacity pair.
- Capacity thresholds need BATT_CAPACITY, and must lie below it (else they trigger at once).
- Voltages are checked per cell (warnings): with the cell count known, each threshold divided by it
  must lie in the chemistry's plausible range (LiPo 3.0..4.35 V); without it, some cell count from
  1 to 14 must put every threshold in that range.
- Arming limits at or below the LOW thresholds would trigger the failsafe right after arming (warning).

No rule language existed when this was written, so the rules are code; each finding names the
parameter it is about so a caller can report that parameter's line.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ...inputs import parameter_files

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
VOLTAGES = ("BATT_LOW_VOLT", "BATT_CRT_VOLT", "BATT_ARM_VOLT")
NONNEGATIVE: tuple[str, ...] = ("BATT_CAPACITY", "BATT_LOW_VOLT", "BATT_CRT_VOLT", "BATT_LOW_MAH", "BATT_CRT_MAH")
NONNEGATIVE += ("BATT_ARM_VOLT", "BATT_ARM_MAH", "BATT_LOW_TIMER")


@dataclass(frozen=True)
class Finding:
    severity: str  # "error" or "warning"
    param: str
    message: str


def _num(values: Mapping[str, object], name: str) -> float:
    value = values.get(name, 0)
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else 0.0


def check_settings(values: Mapping[str, object], *, cells: int | None = None, chemistry: str = "lipo") -> list[Finding]:
    """Every cross-field problem of a BATT_* parameter set (absent parameters count as 0)."""
    if chemistry not in CELL_RANGES:
        raise ValueError(f"expected a chemistry among {', '.join(CELL_RANGES)}, got {chemistry!r}")
    out: list[Finding] = []
    v = {name: _num(values, name) for name in NONNEGATIVE}
    for name in NONNEGATIVE:
        if v[name] < 0:
            out.append(Finding("error", name, f"{name} is {v[name]:g}: expected 0 (disabled) or a positive value"))
    low_v, crt_v, low_m, crt_m, cap = (
        v["BATT_LOW_VOLT"],
        v["BATT_CRT_VOLT"],
        v["BATT_LOW_MAH"],
        v["BATT_CRT_MAH"],
        v["BATT_CAPACITY"],
    )
    if low_v > 0 and crt_v > 0 and crt_v >= low_v:
        out.append(
            Finding("error", "BATT_CRT_VOLT", f"BATT_CRT_VOLT ({crt_v:g} V) must be below BATT_LOW_VOLT ({low_v:g} V)")
        )
    if low_m > 0 and crt_m > 0 and crt_m >= low_m:
        out.append(
            Finding("error", "BATT_CRT_MAH", f"BATT_CRT_MAH ({crt_m:g} mAh) must be below BATT_LOW_MAH ({low_m:g} mAh)")
        )
    for name in ("BATT_LOW_MAH", "BATT_CRT_MAH"):
        if v[name] > 0 and cap <= 0:
            out.append(Finding("error", name, f"{name} needs BATT_CAPACITY (the remaining charge is capacity - used)"))
        elif v[name] > 0 and v[name] >= cap:
            out.append(
                Finding(
                    "error",
                    name,
                    f"{name} ({v[name]:g} mAh) is not below BATT_CAPACITY ({cap:g} mAh): it triggers at once",
                )
            )
    out.extend(_per_cell(v, cells, chemistry))
    arm_v, arm_m = v["BATT_ARM_VOLT"], v["BATT_ARM_MAH"]
    if arm_v > 0 and low_v > 0 and arm_v <= low_v:
        out.append(
            Finding("warning", "BATT_ARM_VOLT", f"BATT_ARM_VOLT ({arm_v:g} V) is not above BATT_LOW_VOLT ({low_v:g} V)")
        )
    if arm_m > 0 and low_m > 0 and arm_m <= low_m:
        out.append(
            Finding(
                "warning", "BATT_ARM_MAH", f"BATT_ARM_MAH ({arm_m:g} mAh) is not above BATT_LOW_MAH ({low_m:g} mAh)"
            )
        )
    return out


def _per_cell(v: Mapping[str, float], cells: int | None, chemistry: str) -> list[Finding]:
    lo, hi = CELL_RANGES[chemistry]
    set_ = [(n, v[n]) for n in VOLTAGES if v[n] > 0]
    if not set_:
        return []
    if cells is not None:
        if cells < 1:
            raise ValueError(f"expected a cell count of at least 1, got {cells}")
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


def check_file(path: Path, *, cells: int | None = None, chemistry: str = "lipo") -> list[tuple[str, int, Finding]]:
    """The findings of a .param / .params file as (file, line of the parameter, finding)."""
    display = path.as_posix()
    entries = parameter_files.load(path, display)
    lines = {e.name: e.line for e in entries}
    out: list[tuple[str, int, Finding]] = []
    for first, values in parameter_files.read_parameter_file(path):
        for finding in check_settings(values, cells=cells, chemistry=chemistry):
            out.append((display, lines.get(finding.param, first), finding))
    return out
