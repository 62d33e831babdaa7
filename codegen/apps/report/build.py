"""Building a report from inputs: read every input, replay the failsafe, lay out the page or the images."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..failsafe.stream import read_parameter_values
from ..gate.selection import Settings
from .fleet import fleet_view
from .gating import apply_gate
from .log_facts import LogFacts, log_facts
from .page import Replay, render
from .plots import Marker
from .png import write_png
from .replay import replay
from .series import InputSeries, read_input


@dataclass
class Report:
    inputs: list[InputSeries]
    replays: dict[str, Replay]
    facts: dict[str, LogFacts] = field(default_factory=dict)  # per input: what the log says about itself


def collect(
    paths: Sequence[Path],
    schema_dir: Path,
    *,
    message: str | None = None,
    params: Path | None = None,
    vehicle: str | None = None,
    gate: Settings | None = None,
    subjects: Sequence[str] = (),
) -> Report:
    """Every input read, gated as ``validate`` gates it, and replayed (a BattgenError for an input that cannot be
    read, or for a selector that names nothing of an input's message). ``subjects``: the ``--cyphal-subject`` pairs
    a CAN capture's Cyphal subjects are read with."""
    inputs = [read_input(p, schema_dir, message=message, subjects=subjects) for p in paths]
    for item in inputs:
        apply_gate(item, gate or Settings())
    override = read_parameter_values(params) if params is not None else None
    report = Report(inputs, {i.source: replay(i, p, params, vehicle) for i, p in zip(inputs, paths, strict=True)})
    for item in inputs:
        end = max((float(s.t[-1]) for s in item.batteries if len(s.t)), default=0.0)
        report.facts[item.source] = log_facts(item.context, end, override, params.as_posix() if params else "")
    return report


def html(report: Report, *, title: str = "") -> str:
    fleet = fleet_view(report.inputs) if len(report.inputs) > 1 else None
    return render(report.inputs, report.replays, report.facts, fleet=fleet, title=title)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", Path(text).name).strip("_") or "input"


def pngs(report: Report, folder: Path) -> list[Path]:
    """One image per battery: ``<input>-battery<N>.png`` in ``folder``."""
    written = []
    for item in report.inputs:
        rep = report.replays.get(item.source, Replay())
        for s in item.batteries:
            path = folder / f"{_slug(item.source)}-battery{s.battery + 1}.png"
            markers = [Marker(e.t, e.level, e.text) for e in rep.events if e.battery == s.battery]
            facts = report.facts.get(item.source)
            write_png(
                s,
                path,
                markers,
                rep.thresholds.get(s.battery, {}),
                armed=facts.armed if facts else (),
                modes=facts.modes if facts else (),
                failsafes=facts.failsafes if facts else (),
                events=facts.events if facts else (),
            )
            written.append(path)
    return written
