"""Many flights on one page: a row per flight and battery, and trends per pack serial across flights.

Flights are ordered as the inputs were given (sort the file names by date to get a time axis); a pack is
followed across flights by its serial number, where the battery reports one. The trends plotted per pack: charge
used, internal resistance (load steps), minimum cell voltage and state of health where the pack reports it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any

from .figures import Figures, compute
from .series import InputSeries

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
    return "—" if value is None else f"{value * scale:.{digits}f}"


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
    by_serial: dict[str, list[tuple[int, Figures]]] = {}
    for flight, item in enumerate(inputs):
        for s in item.batteries:
            f = compute(s)
            rows.append(_row(PurePath(item.source).name, s.label, s.serial, f))
            if s.serial:
                by_serial.setdefault(s.serial, []).append((flight + 1, f))
    data: list[dict[str, Any]] = []
    for serial, points in sorted(by_serial.items()):
        if len(points) < 2:
            continue
        xs = [p for p, _ in points]
        for axis, name, values in (
            ("y", "charge used [mAh]", [f.charge_used_mah for _, f in points]),
            (
                "y2",
                "IR [mΩ]",
                [None if f.internal_resistance_ohm is None else f.internal_resistance_ohm * 1000 for _, f in points],
            ),
        ):
            data.append(
                {
                    "type": "scatter",
                    "mode": "lines+markers",
                    "name": f"{serial} {name}",
                    "x": xs,
                    "y": values,
                    "yaxis": axis,
                }
            )
    layout = {
        "height": 320,
        "margin": {"l": 70, "r": 70, "t": 20, "b": 40},
        "xaxis": {"title": {"text": "flight (input order)"}, "dtick": 1},
        "yaxis": {"title": {"text": "charge used [mAh]"}},
        "yaxis2": {"title": {"text": "internal resistance [mΩ]"}, "overlaying": "y", "side": "right"},
    }
    return FleetView(HEADER, rows, {"data": data, "layout": layout})
