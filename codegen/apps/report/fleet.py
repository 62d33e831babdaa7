"""Many flights on one page: a row per flight and battery, and trends per pack serial across flights.

Each flight row gives the log's start (UTC, from its own clock where it tells it: LogContext) and its firmware. A
pack is followed across flights by its serial number, where the battery reports one; its trends are plotted over
the flights' dates when every input tells its date (else over the flights in input order, as the axis says):
charge used and internal resistance (load steps), and the state of health and cycle count where the pack reports
them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import PurePath
from typing import Any

from .figures import Figures, compute, shown
from .series import InputSeries

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf")
HEADER = [
    "flight",
    "date [UTC]",
    "firmware",
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


def _row(
    source: str, date: str | None, firmware: str | None, label: str, serial: str, f: Figures, per_cell: bool
) -> list[str]:
    """A flight's row; the cell columns "—" where the log's cells are the pack voltage split evenly (no per-cell
    data, as the battery's own figures say)."""
    return [
        source,
        date or "—",
        firmware or "—",
        label,
        _fmt(f.duration_s, 1),
        _fmt(f.min_pack_voltage_v, 2),
        _fmt(f.min_cell_voltage_v if per_cell else None, 3),
        _fmt(f.peak_current_a, 1),
        _fmt(f.charge_used_mah, 0),
        _fmt(f.energy_used_wh, 2),
        _fmt(f.max_cell_imbalance_v if per_cell else None, 0, 1000.0),
        _fmt(f.internal_resistance_ohm, 1, 1000.0),
        serial or "—",
    ]


def _date(item: InputSeries) -> str | None:
    """The log's start in UTC (``2024-03-18 14:49:10``), where the log tells it."""
    start = item.context.start_utc_us if item.context is not None else None
    return None if start is None else datetime.fromtimestamp(start / 1e6, UTC).strftime("%Y-%m-%d %H:%M:%S")


def fleet_view(inputs: Sequence[InputSeries]) -> FleetView:
    rows: list[list[str]] = []
    by_serial: dict[str, list[tuple[int | str, Figures, float | None, int | None]]] = {}
    dates = [_date(item) for item in inputs]
    dated = all(d is not None for d in dates)  # one axis for every pack: dates only when every flight has one
    for flight, item in enumerate(inputs):
        firmware = item.context.firmware if item.context is not None else None
        for s in item.batteries:
            f = compute(s)
            per_cell = s.has_cell_data
            rows.append(_row(PurePath(item.source).name, dates[flight], firmware, s.label, s.serial, f, per_cell))
            if s.serial:
                x: int | str = (dates[flight] or "") if dated else flight + 1
                by_serial.setdefault(s.serial, []).append((x, f, s.state_of_health, s.cycle_count))
    for points in by_serial.values():
        points.sort(key=lambda p: str(p[0]) if dated else int(p[0]))
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
            **({"type": "date"} if dated else {"dtick": 1}),
            "showticklabels": r == len(shown) - 1,
            **({"matches": "x"} if r else {}),
            **(
                {"title": {"text": "log start [UTC]" if dated else "flight (input order)"}}
                if r == len(shown) - 1
                else {}
            ),
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
