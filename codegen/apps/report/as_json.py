"""``battgen report --format json``: the figures the page shows, per input and battery, as data.

Each battery carries the page's figures in the page's units (``charge_used_mah``, ``energy_used_wh``, ...) and,
under ``flight``, the flight figures in SI as the fleet views have them (:mod:`codegen.apps.battery.figures`), so
a script, a CI job or a consistency test reads the same numbers a person reads on the page. Each input carries, under
``log``, what the log says about itself (:class:`codegen.apps.battery.context.LogContext`: firmware, vehicle, start
in UTC, the arming rule and the armed spans up to the last battery record; ``null`` for a data file). Unknown is
``null``; NaN never appears (JSON has none).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from .build import Report
from .figures import compute
from .page import Replay

FORMAT_VERSION = 1


def _clean(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


def report_json(report: Report) -> dict[str, Any]:
    """The report as a JSON-ready document."""
    inputs = []
    for item in report.inputs:
        rep = report.replays.get(item.source, Replay())
        batteries = []
        for s in item.batteries:
            figures = compute(s, rep.thresholds.get(s.battery, {}))
            page = {k: v for k, v in dataclasses.asdict(figures).items() if k != "flight"}
            batteries.append(
                {
                    "battery": s.battery,
                    "label": s.label,
                    "message": s.message,
                    "serial": s.serial or None,
                    "figures": page,
                    "flight": dataclasses.asdict(figures.flight) | {"duration_s": figures.flight.duration_s},
                    "failsafe_events": [
                        {"t": e.t, "level": e.level, "text": e.text} for e in rep.events if e.battery == s.battery
                    ],
                }
            )
        context = item.samples.context if item.samples is not None else None
        end = max((float(s.t[-1]) for s in item.batteries if len(s.t)), default=0.0)
        inputs.append(
            {
                "source": item.source,
                "log": context.to_dict(end) if context is not None else None,
                "message": item.message,
                "records": item.records,
                "findings": sum(g.count for g in item.findings),
                "failsafe_note": rep.note or None,
                "batteries": batteries,
            }
        )
    document: dict[str, Any] = _clean({"format": "battgen-report", "version": FORMAT_VERSION, "inputs": inputs})
    return document
