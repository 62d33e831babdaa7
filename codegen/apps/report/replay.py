"""The failsafe replay shown in a report: which thresholds were crossed when, per battery.

The report replays each battery's samples through the failsafe evaluator with the parameters the user gives
(``--params``); without parameters there is nothing to replay against, and the page says so.
"""

from __future__ import annotations

from pathlib import Path

from .page import Replay
from .series import InputSeries

NO_PARAMS = "no failsafe parameters: give --params FILE (BATT_* values) to replay the failsafe"


def replay(item: InputSeries, params: Path | None, vehicle: str | None) -> Replay:
    """The failsafe events of every battery of one input."""
    if params is None:
        return Replay(note=NO_PARAMS)
    return Replay(note=f"failsafe replay from {params} is not available for this input yet")
