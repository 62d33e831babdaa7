"""Building a report from inputs: read every input, replay the failsafe, lay out the page or the images."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from .fleet import fleet_view
from .page import Replay, render
from .plots import Marker
from .png import write_png
from .replay import replay
from .series import InputSeries, read_input


@dataclass
class Report:
    inputs: list[InputSeries]
    replays: dict[str, Replay]


def collect(
    paths: Sequence[Path],
    schema_dir: Path,
    *,
    message: str | None = None,
    params: Path | None = None,
    vehicle: str | None = None,
) -> Report:
    """Every input read and replayed (a BattgenError for an input that cannot be read)."""
    inputs = [read_input(p, schema_dir, message=message) for p in paths]
    return Report(inputs, {i.source: replay(i, p, params, vehicle) for i, p in zip(inputs, paths, strict=True)})


def html(report: Report, *, title: str = "") -> str:
    fleet = fleet_view(report.inputs) if len(report.inputs) > 1 else None
    return render(report.inputs, report.replays, fleet=fleet, title=title)


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
            write_png(s, path, markers, rep.thresholds.get(s.battery, {}))
            written.append(path)
    return written
