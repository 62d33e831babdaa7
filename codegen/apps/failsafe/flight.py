"""One flight log replayed through the battery failsafe as ``battgen failsafe`` does it, for callers
that want the events as data (the fleet export's events table) rather than printed.

The parameters are given (a parameter file's values) or, for an ArduPilot log, its own (DataFlash PARM records, tlog
PARAM_VALUE frames);
the vehicle is given or detected from them; the situation is the CLI's default (home set, a
position fix, a SmartRTL path, no QuadPlane, no landing sequence), so the events are the ones
``battgen failsafe --json`` prints for the same log and parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import BattgenError
from .columnar import replay_table
from .evaluator import Event, make_failsafe
from .levels import Level
from .logs import SampleTable
from .settings import battery_settings
from .stream import Sample
from .vehicles import detect_vehicle


@dataclass
class FlightReplay:
    """What a replay gave: the events with the sample that caused each, the vehicle, and per
    battery (1-based, as ArduPilot numbers them) the samples read and the level reached."""

    events: list[tuple[Event, Sample]]
    vehicle: str
    vehicle_how: str
    samples: dict[int, int] = field(default_factory=dict)
    levels: dict[int, Level] = field(default_factory=dict)


def replay_flight(table: SampleTable, name: str, values: dict[str, float], vehicle: str | None) -> FlightReplay:
    """Replay a log's samples (:class:`.logs.SampleTable`; errors name the log ``name``) with the parameter
    ``values``."""
    detection = detect_vehicle(values, vehicle)
    try:
        settings = battery_settings(values, detection.vehicle)
    except ValueError as exc:
        raise BattgenError(f"{name}: parameters: {exc}") from None
    fs = make_failsafe(settings, detection.vehicle)
    events, counts = replay_table(fs, table, name)
    out = FlightReplay(events, detection.vehicle.name, detection.how, counts)
    out.levels = {i: m.failsafe for i, m in sorted(fs.monitors.items())}
    return out
