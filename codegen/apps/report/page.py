"""The report page: one self-contained HTML file, plotly's JavaScript embedded, no network fetch.

One section per battery of every input: the figures, the failsafe events, the validation findings grouped by
rule (each with its count and a link to the time it first happened) and the time plots. With more than one
input the page opens with the fleet view (:mod:`.fleet`). The figures' data sits in one JSON block that the
page's script hands to plotly; links to a time zoom the battery's plots to ±10 s around it.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import resources
from pathlib import PurePath
from typing import Any

import jinja2

from ... import __version__
from ...errors import BattgenError
from ...text.escape import line
from ..battery.column_checks import FindingGroup
from ..battery.context import LogText
from ..gate.selection import describe
from .downsample import POINT_BUDGET
from .figures import compute
from .fleet import FleetView
from .log_facts import LogFacts, WarningChange, warning_changes
from .plots import Marker, figure
from .series import BatterySeries, InputSeries, warning_levels

NEEDS_PLOTLY = "the HTML report embeds plotly's JavaScript: pip install 'battgen[report]'"
_CSS = {"LOW": "warn", "CRITICAL": "bad", "error": "bad", "warning": "warn"}


@dataclass(frozen=True)
class FailsafeEvent:
    """A failsafe transition to show: time, battery, level, and the operator text."""

    t: float
    battery: int
    level: str
    text: str


@dataclass
class Replay:
    """The failsafe replay of one input: its events, and a note when there was none (no parameters...)."""

    events: list[FailsafeEvent] = field(default_factory=list)
    note: str = ""
    # battery (0-based, as the series number them) -> {parameter name: volts}, drawn on the voltage plot
    thresholds: dict[int, dict[str, float]] = field(default_factory=dict)


def plotly_js() -> str:
    """plotly.js, minified, from the plotly package (its JavaScript is what the page embeds)."""
    try:
        offline = importlib.import_module("plotly.offline")  # untyped: imported by name
    except ImportError as exc:
        raise BattgenError(NEEDS_PLOTLY) from exc
    return str(offline.get_plotlyjs())


def _grouped(findings: Sequence[FindingGroup], battery: int) -> list[dict[str, object]]:
    groups = [
        {"count": g.count, "t": g.t, "text": g.message, "css": _CSS.get(g.severity, "")}
        for g in findings
        if g.battery == battery
    ]
    return sorted(groups, key=lambda g: (-int(str(g["count"])), str(g["text"])))


def _section(
    s: BatterySeries, findings: Sequence[FindingGroup], replay: Replay, index: int, facts: LogFacts
) -> tuple[dict[str, Any], dict[str, Any]]:
    plot_id = f"plot-{index}"
    events = [e for e in replay.events if e.battery == s.battery]
    markers = [Marker(e.t, e.level, e.text) for e in events]
    warnings = warning_changes(s.t, s.warning, s.battery, warning_levels())
    thresholds = replay.thresholds.get(s.battery, {})
    cells_note = ""
    if s.cells_split_evenly:
        cells_note = f"no per-cell data: the log's {s.cell_count} cell voltages are the pack voltage split evenly"
    context = {
        "id": f"battery-{index}",
        "plot_id": plot_id,
        "label": s.label,
        "serial": s.serial,
        "figures": compute(s, thresholds).rows(per_cell=s.has_cell_data),
        "cells_note": cells_note,
        "events": [{"t": e.t, "level": e.level, "text": e.text, "css": _CSS.get(e.level, "")} for e in events],
        "warnings": [{"t": w.t, "level": w.level, "css": _CSS.get(w.level.upper(), "")} for w in warnings],
        "first_warnings": _first_reached(warnings),
        "failsafe_note": replay.note,
        "findings": _grouped(findings, s.battery),
    }
    fig = figure(
        s,
        markers,
        thresholds,
        armed=facts.armed,
        warnings=warnings,
        soc_thresholds=facts.soc_thresholds,
        modes=facts.modes,
        failsafes=facts.failsafes,
        events=facts.events,
    )
    return context, fig


def render(
    inputs: Sequence[InputSeries],
    replays: Mapping[str, Replay],
    facts: Mapping[str, LogFacts] | None = None,
    *,
    fleet: FleetView | None = None,
    title: str = "",
    now: datetime | None = None,
) -> str:
    """The page's HTML text."""
    env = jinja2.Environment(loader=jinja2.FunctionLoader(_template), autoescape=True, undefined=jinja2.StrictUndefined)
    figures: dict[str, Any] = {}
    sections = []
    index = 0
    for item in inputs:
        replay = replays.get(item.source, Replay())
        own = (facts or {}).get(item.source, LogFacts())
        batteries = []
        for s in item.batteries:
            context, fig = _section(s, item.findings, replay, index, own)
            figures[context["plot_id"]] = fig
            batteries.append(context)
            index += 1
        notices = [n.message for n in item.notices if n.severity != "info"]
        notices += [u.message for u in item.unreadable]
        name = PurePath(item.source).name or item.source
        sections.append(
            {
                "source": item.source,
                "name": name,
                "batteries": batteries,
                "notices": notices,
                "header": own.header,
                "parameters": own.parameters,
                "parameters_from": own.parameters_from,
                "soc_thresholds": [(k, f"{v:g} %") for k, v in own.soc_thresholds.items()],
                "thresholds_from": own.thresholds_from,
                "gate": _gate_text(item),
                "battery_texts": [_text_row(m) for m in own.battery_texts],
                "texts": [_text_row(m) for m in own.texts],
                "failsafes": [{"t": t, "text": line(what)} for t, what in own.failsafes],
                "events": [{"t": t, "text": line(what)} for t, what in own.events],
            }
        )
    fleet_context = None
    if fleet is not None:
        fleet_context = {
            "header": fleet.header,
            "rows": fleet.rows,
            "trends": bool(fleet.trends["data"]),
            "trends_key": "trends",
        }
        if fleet.trends["data"]:
            figures["trends"] = fleet.trends
    stamp = (now or datetime.now(UTC)).strftime("%Y-%m-%d %H:%M UTC")
    count = sum(len(i.batteries) for i in inputs)
    first = PurePath(inputs[0].source).name if inputs else ""
    page_title = title or (first if len(inputs) == 1 else f"{len(inputs)} flights") + " — battery report"
    subtitle = (
        f"{len(inputs)} input(s), {count} battery instance(s); made by battgen {__version__} on {stamp}; "
        f"plots show at most {POINT_BUDGET} points per trace"
    )
    text = json.dumps(figures, allow_nan=False, separators=(",", ":")).replace("</", "<\\/")
    return env.get_template("report.html.j2").render(
        title=page_title,
        subtitle=subtitle,
        version=__version__,
        plotly_js=plotly_js(),
        inputs=sections,
        fleet=fleet_context,
        figures_json=text,
    )


def _text_row(m: LogText) -> dict[str, object]:
    """A logged message for the page: its text with control characters shown, not run (ANSI colours...)."""
    css = {"emergency": "bad", "alert": "bad", "critical": "bad", "error": "bad", "warning": "warn"}
    return {"t": m.t, "severity": m.severity, "text": line(m.text), "css": css.get(m.severity, "")}


def _first_reached(warnings: Sequence[WarningChange]) -> list[dict[str, object]]:
    """Each warning level the firmware set, at the first time it set it (what a person asks first)."""
    first: dict[str, float] = {}
    for w in warnings:
        if w.level != "none":  # back to normal is in the full list
            first.setdefault(w.level, w.t)
    return [{"t": t, "level": level, "css": _CSS.get(level.upper(), "")} for level, t in first.items()]


def _gate_text(item: InputSeries) -> str:
    """What the gate left out of the findings and why (the profile and where it came from), or ""."""
    parts = []
    if item.gate is not None:
        parts += list(describe(item.gate))
        if item.gate.origin:
            parts.append(f"settings from {item.gate.origin}")
    if item.left_out:
        parts += [f"{n} left out: {why}" for why, n in sorted(item.left_out.items())]
    return "; ".join(parts)


def _template(name: str) -> str:
    return resources.files(__package__).joinpath("templates", name).read_text(encoding="utf-8")
