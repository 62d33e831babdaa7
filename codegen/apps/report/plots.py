"""The plotly figure of one battery: time plots sharing one time axis, failsafe events marked across them.

Rows (each only when the battery reports it): pack voltage with the failsafe thresholds, current, power, state of
charge (on 0-100 %, with PX4's BAT_*_THR lines), temperature, every cell (with a legend), and the cell imbalance
(max - min); no cell rows where the log's cells are the pack voltage split evenly (no per-cell data). The log's
armed spans are shaded across every row, and the firmware's own warning levels marked (dotted) beside the
replayed failsafe events (solid). Traces are decimated to the point budget of
:mod:`.downsample`; every trace's ``meta`` holds its sample count before decimation, so a reader (or the browser
test) can tell what was drawn from what was read.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..battery.columns import NDArray
from .downsample import POINT_BUDGET, decimate
from .log_facts import WarningChange
from .series import BatterySeries

ROW_HEIGHT = 190
LEVEL_COLOURS = {"LOW": "#d98200", "CRITICAL": "#c62828", "NONE": "#2e7d32"}
MODE_FILLS = ("#e3f2fd", "#fff3e0", "#f3e5f5", "#e8f5e9", "#fce4ec", "#e0f7fa", "#f9fbe7", "#efebe9")
FAILSAFE_COLOUR = "#6a1b9a"
EVENT_COLOUR = "#78909c"
WARNING_COLOURS = {"none": "#2e7d32", "low": "#d98200", "critical": "#c62828", "emergency": "#8e0000"}
ARMED_FILL = "rgba(46, 125, 50, 0.08)"


@dataclass(frozen=True)
class Marker:
    """A failsafe event drawn on the time axis."""

    t: float
    level: str
    text: str  # e.g. "LOW: RTL (voltage 10.4 V < 10.5 V)"


def _rows(s: BatterySeries) -> list[tuple[str, str, list[tuple[str, NDArray]]]]:
    """(title, unit, traces) per row, leaving out rows the battery has no values for."""
    rows: list[tuple[str, str, list[tuple[str, NDArray]]]] = [
        ("pack voltage", "V", [("pack voltage", s.pack_voltage)]),
        ("current", "A", [("current", s.current)]),
        ("power", "W", [("power", s.power)]),
        ("state of charge", "%", [("state of charge", s.state_of_charge)]),
        ("temperature", "°C", [("temperature", s.temperature)]),
    ]
    if s.has_cell_data:
        rows += [
            ("cells", "V", [(f"cell {k + 1}", s.cell(k)) for k in range(s.cell_count)]),
            ("cell imbalance", "mV", [("max - min", s.imbalance * 1000)]),
        ]
    return [
        (title, unit, [(n, v) for n, v in traces if not np.isnan(v).all()])
        for title, unit, traces in rows
        if any(not np.isnan(v).all() for _, v in traces)
    ]


def figure(
    s: BatterySeries,
    markers: Sequence[Marker] = (),
    thresholds: dict[str, float] | None = None,
    budget: int = POINT_BUDGET,
    *,
    armed: Sequence[tuple[float, float]] = (),
    warnings: Sequence[WarningChange] = (),
    soc_thresholds: dict[str, float] | None = None,
    modes: Sequence[tuple[float, str]] = (),
    failsafes: Sequence[tuple[float, str]] = (),
    events: Sequence[tuple[float, str]] = (),
) -> dict[str, Any]:
    """The figure as plotly JSON data (``{"data": [...], "layout": {...}}``), built without plotly's Python API
    so that the page's JSON is exactly what this module says. ``armed``: the log's armed spans; ``warnings``: the
    firmware's own warning changes; ``soc_thresholds``: name -> percent, drawn on the state of charge; ``modes``: the
    flight-mode changes (t, name), a strip above the plots; ``failsafes``: the firmware's own failsafe entries;
    ``events``: the events it logged (ArduPilot's EV records), thin dotted lines named on hover."""
    rows = _rows(s)
    data: list[dict[str, Any]] = []
    layout: dict[str, Any] = {
        "height": max(1, len(rows)) * ROW_HEIGHT + 60,
        "margin": {"l": 70, "r": 90, "t": 44, "b": 40},
        "showlegend": False,
        "legend": {"x": 1.01, "xanchor": "left", "yanchor": "top", "font": {"size": 10}},
        "hovermode": "x unified",
        "shapes": [],
        "annotations": [],
        "template": None,
        "plot_bgcolor": "#fafafa",
    }
    gap = 0.04
    height = (1.0 - gap * (len(rows) - 1)) / max(1, len(rows))
    for r, (title, unit, traces) in enumerate(rows):
        axis = "" if r == 0 else str(r + 1)
        top = 1.0 - r * (height + gap)
        layout[f"xaxis{axis}"] = {
            "matches": "x" if r else None,
            "showticklabels": r == len(rows) - 1,
            "title": {"text": "time [s]"} if r == len(rows) - 1 else None,
            "anchor": f"y{axis}",
            "domain": [0, 1],
        }
        layout[f"yaxis{axis}"] = {
            "title": {"text": f"{title} [{unit}]", "font": {"size": 11}},
            "domain": [max(0.0, top - height), top],
            "anchor": f"x{axis}",
        }
        if title == "state of charge" and _within(traces, 0.0, 100.0):  # a gauge, not a 0.04 % wiggle
            layout[f"yaxis{axis}"]["range"] = [0, 100]
        legend = title == "cells"  # six overlapping traces need their names
        if legend:
            layout["showlegend"] = True
            layout["legend"]["y"] = top
        for name, values in traces:
            xs, ys = decimate(s.t, values, budget)
            data.append(
                {
                    "type": "scattergl" if len(xs) > 5000 else "scatter",
                    "mode": "lines",
                    "name": name,
                    "x": xs,
                    "y": ys,
                    "xaxis": f"x{axis}",
                    "yaxis": f"y{axis}",
                    "line": {"width": 1.2},
                    "showlegend": legend,
                    "meta": {"row": title, "samples": int((~np.isnan(values)).sum())},
                    "hovertemplate": f"%{{y:.3f}} {unit}<extra>{name}</extra>",
                }
            )
        if title == "pack voltage":
            for k, (name, volts) in enumerate(v for v in (thresholds or {}).items() if v[1] > 0):
                _level_line(layout, f"y{axis}", volts, name, k)
        if title == "state of charge":
            for k, (name, percent) in enumerate((soc_thresholds or {}).items()):
                _level_line(layout, f"y{axis}", percent, name, k)
    _shade(layout, armed)
    _warnings(layout, warnings)
    end = float(s.t[-1]) if len(s.t) else 0.0
    _modes(layout, modes, end)
    _failsafes(layout, failsafes)
    _events(layout, events)
    for m in markers:
        colour = LEVEL_COLOURS.get(m.level, "#555")
        layout["shapes"].append(_across(m.t, {"color": colour, "width": 2}, f"failsafe {m.level}"))
        layout["annotations"].append(_label(m.t, 1.0, m.level, colour, 11, yanchor="bottom", hovertext=m.text))
    for key in list(layout):
        if key.startswith("xaxis") and layout[key].get("matches") is None:
            layout[key].pop("matches", None)
    return {"data": data, "layout": layout}


def _within(traces: Sequence[tuple[str, NDArray]], low: float, high: float) -> bool:
    values = np.concatenate([v[~np.isnan(v)] for _, v in traces]) if traces else np.zeros(0)
    return bool(len(values)) and bool(values.min() >= low and values.max() <= high)


def _level_line(layout: dict[str, Any], yref: str, y: float, name: str, k: int = 0) -> None:
    """A threshold across a row, named near its right end (the ``k``-th of a row a label's width further left,
    so that close thresholds -- 7 % and 5 % -- keep readable names)."""
    layout["shapes"].append(
        {
            "type": "line",
            "xref": "x domain",
            "x0": 0,
            "x1": 1,
            "yref": yref,
            "y0": y,
            "y1": y,
            "line": {"dash": "dash", "width": 1, "color": "#888"},
            "name": f"threshold {name}",
        }
    )
    layout["annotations"].append(
        {
            "xref": "x domain",
            "x": 1 - 0.16 * k,
            "yref": yref,
            "y": y,
            "text": name,
            "showarrow": False,
            "xanchor": "right",
            "yanchor": "bottom",
            "font": {"size": 10, "color": "#666"},
        }
    )


def _across(t: float, line: dict[str, Any], name: str) -> dict[str, Any]:
    """A vertical line at ``t`` across every row (a shape named for the tests and readers of the JSON)."""
    return {
        "type": "line",
        "xref": "x",
        "x0": t,
        "x1": t,
        "yref": "paper",
        "y0": 0,
        "y1": 1,
        "line": line,
        "name": name,
    }


def _label(t: float, y: float, text: str, colour: str, size: int, **placed: Any) -> dict[str, Any]:
    """A marker's name at ``t`` s, ``y`` of the plot's height; ``placed``: plotly's anchors, shifts, hover text."""
    where = {"xref": "x", "x": t, "yref": "paper", "y": y, "text": text, "showarrow": False}
    return where | placed | {"font": {"color": colour, "size": size}}


def _band(x0: float, x1: float, y0: float, y1: float, fill: str, name: str, **style: Any) -> dict[str, Any]:
    """A rectangle from ``x0`` to ``x1`` s, ``y0`` to ``y1`` of the plot's height."""
    box = {"type": "rect", "xref": "x", "x0": x0, "x1": x1, "yref": "paper", "y0": y0, "y1": y1}
    return box | {"fillcolor": fill, "name": name, **style}


def _shade(layout: dict[str, Any], armed: Sequence[tuple[float, float]]) -> None:
    """The armed spans, behind every row."""
    for start, end in armed:
        layout["shapes"].append(_band(start, end, 0, 1, ARMED_FILL, "armed", line={"width": 0}, layer="below"))


def _warnings(layout: dict[str, Any], changes: Sequence[WarningChange]) -> None:
    """The firmware's own warning level at each change, dotted; labelled at the foot of the plot where a level is
    first reached (a level flickering near its threshold changes dozens of times: the labels would overprint)."""
    seen: set[str] = set()
    for w in changes:
        colour = WARNING_COLOURS.get(w.level, "#555")
        layout["shapes"].append(_across(w.t, {"color": colour, "width": 1.5, "dash": "dot"}, f"log warning {w.level}"))
        if w.level in seen or w.level == "none":  # back to none: the line says it
            continue
        seen.add(w.level)
        shift = -12 * (len(seen) - 1)  # first low, critical, emergency: often seconds apart
        layout["annotations"].append(_label(w.t, 0, f"log: {w.level}", colour, 10, yanchor="top", yshift=shift))


def _modes(layout: dict[str, Any], modes: Sequence[tuple[float, str]], end: float) -> None:
    """The flight modes as a strip of bands above the plots, one colour per mode name, each named at its start."""
    colours: dict[str, str] = {}
    span = max(end - (modes[0][0] if modes else 0.0), 1e-9)
    for k, (start, name) in enumerate(modes):
        stop = modes[k + 1][0] if k + 1 < len(modes) else end
        if stop <= start:
            continue
        base = name.split(" (", 1)[0]  # ArduPilot's reason aside: one colour per mode
        same = k > 0 and modes[k - 1][1].split(" (", 1)[0] == base  # the mode set again: one band goes on
        colour = colours.setdefault(base, MODE_FILLS[len(colours) % len(MODE_FILLS)])
        layout["shapes"].append(
            _band(start, stop, 1.0, 1.035, colour, f"mode {name}", line={"width": 0.5, "color": "#b0bec5"})
        )
        if same or (stop - start) / span < 0.02:  # no label on a sliver: it would overprint the next
            continue
        hover = f"{name} from {start:.1f} s"
        layout["annotations"].append(_label(start, 1.0175, base, "#37474f", 9, xanchor="left", hovertext=hover))
    if modes:
        layout["margin"]["t"] = max(layout["margin"]["t"], 60)


def _events(layout: dict[str, Any], events: Sequence[tuple[float, str]]) -> None:
    """The events the firmware logged: a thin long-dashed grey line each, named on hover, ``ev`` at the top of the
    plots (a log holds a handful: arming, landing, motor interlock, EKF resets). Dotted lines are the warnings'."""
    for t, what in events:
        style = {"color": EVENT_COLOUR, "width": 1, "dash": "longdash"}
        layout["shapes"].append(_across(t, style, f"log event {what}"))
        layout["annotations"].append(_label(t, 1.0, "ev", EVENT_COLOUR, 9, yanchor="top", hovertext=what))


def _failsafes(layout: dict[str, Any], failsafes: Sequence[tuple[float, str]]) -> None:
    """The firmware's own failsafe entries (PX4 vehicle_status.failsafe, ArduPilot's failsafe MODE and ERR)."""
    for t, what in failsafes:
        style = {"color": FAILSAFE_COLOUR, "width": 2, "dash": "dashdot"}
        layout["shapes"].append(_across(t, style, f"log failsafe {what}"))
        layout["annotations"].append(
            _label(t, 0.5, "log failsafe", FAILSAFE_COLOUR, 10, textangle=-90, xanchor="right", hovertext=what)
        )
