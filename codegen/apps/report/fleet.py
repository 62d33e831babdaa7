"""Many flights on one page: a row per flight and battery, and trends per pack serial across flights.

Flights are ordered as the inputs were given (sort the file names by date to get a time axis); a pack is
followed across flights by its serial number, where the battery reports one. The trends plotted per pack: charge
used and internal resistance (load steps), and the state of health and cycle count where the pack reports them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any

from .figures import Figures, compute, shown
from .series import InputSeries

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf")
HEADER = [
    "flight",
    "battery",
    "duration [s]",
    "min pack [V]",
    "min cell [V]",
    "peak current [A]",
    "charge used [mAh]",
    "energy used [Wh]",
    "max imbalance [mV]",
    "IR [mΩ]",
    "serial",
]


@dataclass(frozen=True)
class FleetView:
    header: list[str]
    rows: list[list[str]]
    trends: dict[str, Any]  # a plotly figure (empty data when no pack is seen twice)


def _fmt(value: float | None, digits: int, scale: float = 1.0) -> str:
    return "—" if value is None else shown(value * scale, digits)


def _row(source: str, label: str, serial: str, f: Figures) -> list[str]:
    return [
        source,
        label,
        _fmt(f.duration_s, 1),
        _fmt(f.min_pack_voltage_v, 2),
        _fmt(f.min_cell_voltage_v, 3),
        _fmt(f.peak_current_a, 1),
        _fmt(f.charge_used_mah, 0),
        _fmt(f.energy_used_wh, 2),
        _fmt(f.max_cell_imbalance_v, 0, 1000.0),
        _fmt(f.internal_resistance_ohm, 1, 1000.0),
        serial or "—",
    ]


def fleet_view(inputs: Sequence[InputSeries]) -> FleetView:
    rows: list[list[str]] = []
    by_serial: dict[str, list[tuple[int, Figures, float | None, int | None]]] = {}
    for flight, item in enumerate(inputs):
        for s in item.batteries:
            f = compute(s)
            rows.append(_row(PurePath(item.source).name, s.label, s.serial, f))
            if s.serial:
                by_serial.setdefault(s.serial, []).append((flight + 1, f, s.state_of_health, s.cycle_count))
    quantities = (
        ("charge used [mAh]", lambda p: p[1].charge_used_mah),
        (
            "internal resistance [mΩ]",
            lambda p: None if p[1].internal_resistance_ohm is None else p[1].internal_resistance_ohm * 1000,
        ),
        ("state of health [%]", lambda p: p[2]),
        ("cycles", lambda p: None if p[3] is None else float(p[3])),
    )
    series = {serial: points for serial, points in sorted(by_serial.items()) if len(points) >= 2}
    shown = [
        (name, get) for name, get in quantities if any(get(p) is not None for points in series.values() for p in points)
    ]
    data: list[dict[str, Any]] = []
    layout: dict[str, Any] = {
        "height": 150 * max(1, len(shown)) + 70,
        "margin": {"l": 70, "r": 20, "t": 20, "b": 40},
        "showlegend": True,
        "legend": {"orientation": "h", "y": -0.12},
    }
    height = 1.0 / max(1, len(shown))
    for r, (name, get) in enumerate(shown):
        axis = "" if r == 0 else str(r + 1)
        layout[f"xaxis{axis}"] = {
            "anchor": f"y{axis}",
            "dtick": 1,
            "showticklabels": r == len(shown) - 1,
            **({"matches": "x"} if r else {}),
            **({"title": {"text": "flight (input order)"}} if r == len(shown) - 1 else {}),
        }
        layout[f"yaxis{axis}"] = {
            "title": {"text": name, "font": {"size": 11}},
            "anchor": f"x{axis}",
            "domain": [1.0 - (r + 1) * height + 0.04, 1.0 - r * height],
        }
        for k, (serial, points) in enumerate(series.items()):
            data.append(
                {
                    "type": "scatter",
                    "mode": "lines+markers",
                    "name": f"pack {serial}",
                    "legendgroup": serial,
                    "showlegend": r == 0,
                    "x": [p[0] for p in points],
                    "y": [get(p) for p in points],
                    "xaxis": f"x{axis}",
                    "yaxis": f"y{axis}",
                    "line": {"color": _COLOURS[k % len(_COLOURS)]},
                    "meta": {"serial": serial, "quantity": name},
                }
            )
    return FleetView(HEADER, rows, {"data": data, "layout": layout})
