"""Static images of a report, one PNG per battery, for tickets and documents (matplotlib, no browser).

The same rows as the HTML plots (:mod:`.plots`), one panel each on a shared time axis, failsafe events as
vertical lines; what the log says of the flight as the page shows it: armed spans shaded, flight modes named
above the top panel, the firmware's own failsafe entries dashed, its logged events (ArduPilot's EV) thin and
grey. matplotlib comes with the ``report`` extra.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ...errors import BattgenError
from .plots import EVENT_COLOUR, LEVEL_COLOURS, figure
from .series import BatterySeries

NEEDS_MATPLOTLIB = "--format png draws with matplotlib: pip install 'battgen[report]'"
ARMED_COLOUR, FAILSAFE_COLOUR = "#2a9d8f", "#c0392b"


def write_png(
    s: BatterySeries,
    path: Path,
    markers: list[Any],
    thresholds: dict[str, float],
    *,
    armed: Sequence[tuple[float, float]] = (),
    modes: Sequence[tuple[float, str]] = (),
    failsafes: Sequence[tuple[float, str]] = (),
    events: Sequence[tuple[float, str]] = (),
) -> None:
    """One image of a battery's plots; ``armed``, ``modes``, ``failsafes`` and ``events`` as :func:`.plots.figure`
    takes them."""
    try:
        matplotlib = importlib.import_module("matplotlib")
        matplotlib.use("Agg")  # no screen: draw into memory
        pyplot = importlib.import_module("matplotlib.pyplot")
    except ImportError as exc:
        raise BattgenError(NEEDS_MATPLOTLIB) from exc
    fig_data = figure(s, markers, thresholds)
    rows: dict[str, list[dict[str, Any]]] = {}
    for trace in fig_data["data"]:
        rows.setdefault(trace["meta"]["row"], []).append(trace)
    count = max(1, len(rows))
    fig, axes = pyplot.subplots(count, 1, sharex=True, figsize=(11, 1.9 * count + 0.8), squeeze=False)
    try:
        for ax, (title, traces) in zip(axes[:, 0], rows.items(), strict=False):
            for trace in traces:
                ax.plot(trace["x"], [float("nan") if y is None else y for y in trace["y"]], linewidth=0.9)
            unit = trace["hovertemplate"].split(" ", 1)[1].split("<", 1)[0]
            ax.set_ylabel(f"{title}\n[{unit}]", fontsize=8)
            ax.grid(True, alpha=0.3)
            for start, stop in armed:
                ax.axvspan(start, stop, color=ARMED_COLOUR, alpha=0.10, linewidth=0)
            for t, _ in failsafes:
                ax.axvline(t, color=FAILSAFE_COLOUR, linestyle="--", linewidth=1.0)
            for t, _ in events:
                ax.axvline(t, color=EVENT_COLOUR, linestyle=(0, (8, 3)), linewidth=0.6)
            for m in markers:
                ax.axvline(m.t, color=LEVEL_COLOURS.get(m.level, "#555"), linewidth=1.5)
            if title == "pack voltage":
                for name, volts in thresholds.items():
                    ax.axhline(volts, linestyle="--", linewidth=0.8, color="#888")
                    ax.text(1.0, volts, name, transform=ax.get_yaxis_transform(), ha="right", va="bottom", fontsize=7)
        top = axes[0, 0]
        for t, name in modes:  # each mode named where it starts, above the top panel
            top.axvline(t, color="#999", linewidth=0.6)
            top.text(t, 1.02, name, transform=top.get_xaxis_transform(), rotation=30, fontsize=6, va="bottom")
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle(f"{s.source} — {s.label}", fontsize=10)
        fig.tight_layout()
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=110)
    finally:
        pyplot.close(fig)
