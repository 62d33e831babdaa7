"""Battery failsafe parameters proposed from a devicetree simple-battery node.

BATT_CAPACITY comes from ``charge-full-design-microamp-hours``; BATT_LOW_VOLT / BATT_CRT_VOLT are
the open-circuit voltages at 20 % / 10 % state of charge (configurable) read off an
``ocv-capacity-table-N`` by linear interpolation, times the cell count. What the node supports is
proposed and the rest named in ``Result.warnings``: a node without a table gets BATT_CAPACITY alone,
a table that does not reach a threshold's state of charge leaves that voltage out. The cell count is given, or
inferred from ``voltage-max-design-microvolt`` (else ``-min-``) and the chemistry's per-cell
voltage; a table whose voltages exceed any single cell's is taken as a whole-pack table.
Each proposal says where its value came from, for the comment in the written .param file.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ...errors import BattgenError

# device-chemistry -> (name for the checks, full cell voltage, empty cell voltage)
CHEMISTRY: dict[str, tuple[str, float, float]] = {
    "lithium-ion": ("lion", 4.2, 3.0),
    "lithium-ion-polymer": ("lipo", 4.2, 3.0),
    "lithium-ion-manganese-oxide": ("limn", 4.2, 3.0),
    "lithium-ion-iron-phosphate": ("life", 3.65, 2.5),
    "nickel-metal-hydride": ("nimh", 1.45, 1.0),
    "nickel-cadmium": ("nicd", 1.45, 1.0),
}
DEFAULT_CHEMISTRY = "lithium-ion-polymer"
MAX_CELL_VOLTS = 4.5  # above this a table cannot be a single cell's


@dataclass(frozen=True)
class Proposal:
    name: str
    value: int | float
    comment: str


@dataclass(frozen=True)
class Result:
    proposals: tuple[Proposal, ...]
    cells: int
    chemistry: str  # the checks' name (lipo, life...)
    notes: tuple[str, ...]  # header lines: what was assumed
    warnings: tuple[str, ...] = ()  # what the node could not give (a parameter not proposed, and why)


def _scalar(value: Any) -> float | None:
    """dt-schema wraps cells in lists (``[[9900000]]``); take the single number inside."""
    while isinstance(value, list) and len(value) == 1:
        value = value[0]
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    return None


def _table(value: Any) -> list[tuple[float, float]] | None:
    """``ocv-capacity-table-N``: (microvolt, percent) pairs, as nested or flat cells."""
    if not isinstance(value, list):
        return None
    flat: list[Any] = []
    for item in value:
        flat.extend(item if isinstance(item, list) else [item])
    if len(flat) < 4 or len(flat) % 2 or not all(isinstance(x, int) for x in flat):
        return None
    return [(flat[i] / 1e6, float(flat[i + 1])) for i in range(0, len(flat), 2)]


def voltage_at(table: Sequence[tuple[float, float]], soc_percent: float) -> float:
    """The open-circuit voltage at ``soc_percent`` by linear interpolation between table rows."""
    rows = sorted(table, key=lambda r: r[1])
    if not rows[0][1] <= soc_percent <= rows[-1][1]:
        raise BattgenError(f"{soc_percent:g} % is outside the OCV table ({rows[0][1]:g}..{rows[-1][1]:g} %)")
    for (v0, p0), (v1, p1) in itertools.pairwise(rows):
        if p0 <= soc_percent <= p1:
            return v0 if p1 == p0 else v0 + (v1 - v0) * (soc_percent - p0) / (p1 - p0)
    return rows[-1][0]


def _pick_table(
    props: Mapping[str, Any], index: int | None, where: str
) -> tuple[int, list[tuple[float, float]]] | None:
    """The OCV table to read voltages from (None: the node has none)."""
    tables = {}
    for name, value in props.items():
        if name.startswith("ocv-capacity-table-") and name.rsplit("-", 1)[1].isdigit():
            table = _table(value)
            if table is None:
                raise BattgenError(f"{where}: expected {name} as <microvolt percent> pairs")
            tables[int(name.rsplit("-", 1)[1])] = table
    if not tables and index is None:
        return None
    if index is not None:
        if index not in tables:
            raise BattgenError(f"{where}: no ocv-capacity-table-{index} (have {sorted(tables)})")
        return index, tables[index]
    temps = props.get("ocv-capacity-celsius")
    flat = [t for t in (temps if isinstance(temps, list) else []) for t in (t if isinstance(t, list) else [t])]
    if flat and all(isinstance(t, int) for t in flat):  # the table nearest room temperature
        best = min((i for i in tables if i < len(flat)), key=lambda i: abs(flat[i] - 20), default=min(tables))
        return best, tables[best]
    return min(tables), tables[min(tables)]


def propose(
    props: Mapping[str, Any],
    *,
    where: str,
    lines: Mapping[str, str],
    cells: int | None = None,
    low_soc: float = 20.0,
    critical_soc: float = 10.0,
    table: int | None = None,
    mah_thresholds: bool = False,
) -> Result:
    """Proposals from a simple-battery node's properties (``node_to_model_dict`` form).

    ``lines`` maps property names to where they are written (``bat.dts:6``) for the comments."""
    if not 0 <= critical_soc < low_soc <= 100:
        raise BattgenError(f"expected 0 <= critical SOC < low SOC <= 100, got {critical_soc:g} and {low_soc:g}")

    def at(name: str) -> str:
        return f"{name}, {lines[name]}" if name in lines else name

    notes: list[str] = []
    chem_text = props.get("device-chemistry")
    if not isinstance(chem_text, str):
        chem_text = DEFAULT_CHEMISTRY
        notes.append(f"no device-chemistry: assuming {DEFAULT_CHEMISTRY}")
    if chem_text not in CHEMISTRY:
        raise BattgenError(f"{where}: expected a device-chemistry among {', '.join(CHEMISTRY)}, got {chem_text!r}")
    chem, cell_full, cell_empty = CHEMISTRY[chem_text]

    vmax = _scalar(props.get("voltage-max-design-microvolt"))
    vmin = _scalar(props.get("voltage-min-design-microvolt"))
    if cells is not None:
        if cells < 1:
            raise BattgenError(f"expected a cell count of at least 1, got {cells}")
        notes.append(f"{chem_text}, {cells} cells (given)")
    elif vmax:
        cells = max(1, round(vmax / 1e6 / cell_full))
        notes.append(
            f"{chem_text}, {cells} cells: voltage-max-design {vmax / 1e6:g} V / {cell_full:g} V per cell "
            f"({at('voltage-max-design-microvolt')})"
        )
    elif vmin:
        cells = max(1, round(vmin / 1e6 / cell_empty))
        notes.append(
            f"{chem_text}, {cells} cells: voltage-min-design {vmin / 1e6:g} V / {cell_empty:g} V per cell "
            f"({at('voltage-min-design-microvolt')})"
        )
    out: list[Proposal] = []
    warnings: list[str] = []
    charge = _scalar(props.get("charge-full-design-microamp-hours"))
    capacity = round(charge / 1000) if charge else None
    if capacity:
        src = "charge-full-design-microamp-hours"
        out.append(Proposal("BATT_CAPACITY", capacity, f"{src} = {charge:.0f} uAh ({at(src)})"))
    else:
        warnings.append("no charge-full-design-microamp-hours: BATT_CAPACITY not proposed")

    # the voltages: from the part of the OCV table the node has (seed 004's binding example covers 90..100 %
    # only, and most boards' nodes have no table at all): what cannot be read off it is named, not guessed
    picked = _pick_table(props, table, where)
    if picked is None:
        warnings.append("no ocv-capacity-table-N: BATT_LOW_VOLT and BATT_CRT_VOLT not proposed")
    elif cells is None:
        warnings.append(
            "no voltage-max/min-design-microvolt to count the cells by: BATT_LOW_VOLT and BATT_CRT_VOLT not "
            "proposed (give --cells)"
        )
    else:
        index, rows = picked
        src = f"ocv-capacity-table-{index}"
        per_pack = max(v for v, _ in rows) > MAX_CELL_VOLTS
        factor = 1 if per_pack else cells
        for name, soc in (("BATT_LOW_VOLT", low_soc), ("BATT_CRT_VOLT", critical_soc)):
            try:
                volts = voltage_at(rows, soc)
            except BattgenError as exc:
                warnings.append(f"{name} not proposed: {exc} ({at(src)})")
                continue
            how = f"{volts:.3f} V (whole pack)" if per_pack else f"{volts:.3f} V per cell x {cells} cells"
            out.append(Proposal(name, round(volts * factor, 2), f"OCV at {soc:g} % SOC: {how} ({at(src)})"))
    if mah_thresholds and capacity:
        for name, soc in (("BATT_LOW_MAH", low_soc), ("BATT_CRT_MAH", critical_soc)):
            out.append(Proposal(name, round(capacity * soc / 100), f"{soc:g} % of BATT_CAPACITY"))
    if not out:
        raise BattgenError(f"{where}: expected charge-full-design-microamp-hours or an ocv-capacity-table-N, found "
                           f"neither: nothing to propose ({'; '.join(warnings)})")  # fmt: skip
    return Result(tuple(out), cells or 0, chem, tuple(notes), tuple(warnings))
