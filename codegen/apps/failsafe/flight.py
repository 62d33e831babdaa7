"""One flight log replayed through the battery failsafe as ``battgen failsafe`` does it, for callers
that want the events as data (the fleet export's events table) rather than printed.

The parameters are given (a parameter file's values) or, for a DataFlash log, its own PARM records;
the vehicle is given or detected from them; the situation is the CLI's default (home set, a
position fix, a SmartRTL path, no QuadPlane, no landing sequence), so the events are the ones
``battgen failsafe --json`` prints for the same log and parameters.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import BattgenError
from .evaluator import Event, make_failsafe
from .levels import Level
from .logs import SampleTable
from .settings import battery_settings
from .stream import Reader, Replay, Sample, open_reader
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


@functools.cache
def _reader() -> Reader:
    """The JSON Lines reader a Replay holds (a flight log's samples bypass it): the schemas loaded
    once per process, not once per log."""
    return open_reader(None)


def replay_flight(table: SampleTable, name: str, values: dict[str, float], vehicle: str | None) -> FlightReplay:
    """Replay a log's samples (:class:`.logs.SampleTable`; errors name the log ``name``) with the parameter
    ``values``."""
    detection = detect_vehicle(values, vehicle)
    try:
        settings = battery_settings(values, detection.vehicle)
    except ValueError as exc:
        raise BattgenError(f"{name}: parameters: {exc}") from None
    fs = make_failsafe(settings, detection.vehicle)
    replay = Replay(fs, _reader())
    out = FlightReplay([], detection.vehicle.name, detection.how)

    def samples_of() -> Iterator[Sample]:
        for sample in table.samples():
            out.samples[sample.instance] = out.samples.get(sample.instance, 0) + 1
            yield sample

    out.events.extend(replay.run(Path(name), name, samples_of()))
    out.levels = {i: m.failsafe for i, m in sorted(fs.monitors.items())}
    return out
