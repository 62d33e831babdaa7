"""The Rust crate's failsafe replay data, written by the Python side at test time: the random armed streams
the Python failsafe evaluator is tested on (tests/failsafe_streams.py, the same strategies as the columnar
replay's test), each with its vehicle, variants, situation and every battery's BATT_* settings, and the events
the Python evaluator gives, sample by sample. The crate's harness (``rust_failsafe_replay.rs`` beside the test)
feeds the same samples to ``battgen::failsafe::Failsafe`` and must print the same event lines.

One line a record, fields split by spaces; floats as the 16 hex digits of their IEEE bits (exact both ways),
``-`` for unknown; an event line ends with ``|action name|ArduPilot's text``::

    case VEHICLE SEED_CRITICAL DISTANCE HOME_SET POSITION_FIX SMART_RTL_READY QUADPLANE LANDING_SEQUENCE
    settings INSTANCE CAPACITY LOW_VOLT LOW_TIMER LOW_MAH CRT_VOLT CRT_MAH LOW_ACT CRT_ACT VOLTSRC MONITOR
    sample MS INSTANCE ARMED VOLTS AMPS MAH DISTANCE_TO_HOME
    event MS BATTERY LEVEL CAUSE ACTION EXECUTED OUTCOME PRIORITY VALUE THRESHOLD VOLTAGE CONSUMED SOURCE|NAME|TEXT
    end
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from failsafe_streams import ROW, VALUES, Row, table_of, timed
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from codegen.apps.failsafe.evaluator import DISTANCE, SEED_CRITICAL, Event, make_failsafe
from codegen.apps.failsafe.settings import battery_settings
from codegen.apps.failsafe.vehicles import VEHICLES, Situation

HARNESS = Path(__file__).parent / "backends" / "rust_failsafe_replay.rs"
EXAMPLES = 300  # as many streams as the columnar replay's test draws
FLIGHTS = 200
VARIANTS: tuple[tuple[str, ...], ...] = ((), (SEED_CRITICAL,), (DISTANCE,), (SEED_CRITICAL, DISTANCE))


def bits(value: float | None) -> str:
    return "-" if value is None else struct.pack(">d", value).hex()


def _flag(value: bool) -> str:
    return "1" if value else "0"


def event_line(e: Event) -> str:
    head = (
        f"event {round(e.time * 1000)} {e.battery} {e.level.name.lower()} {e.cause} {e.action_code} "
        f"{_flag(e.executed)} {e.outcome.replace(' ', '_')} {e.priority} {bits(e.value)} {bits(e.threshold)} "
        f"{bits(e.voltage)} {bits(e.consumed_mah)} {e.voltage_source}"
    )
    return f"{head}|{e.action}|{e.ardupilot_text}"


@dataclass
class Stream:
    lines: list[str]
    events: int
    variants: tuple[str, ...]


def flight_rows(n: int, dt_ms: int, start_v: float, drop_v_per_s: float, amps: float, disarm_at: int,
                two: bool, logged_mah: bool) -> list[Row]:  # fmt: skip
    """A discharge as a flight gives it (the random streams above rarely hold a voltage below a threshold
    for longer than its timer): the voltage falls and sags with the current, the current varies, the
    charge is logged or left to be integrated, a second battery alternates, the vehicle disarms at
    ``disarm_at`` and arms again ten samples later."""
    rows: list[Row] = []
    used = 0.0
    for k in range(n):
        t = k * dt_ms / 1000
        a = round(amps * (1 + ((k % 7) - 3) / 10), 1)
        v = round(start_v - drop_v_per_s * t - a * 0.004 * (k % 3), 2)
        used += a * dt_ms / 3600
        armed = 0.0 if disarm_at <= k < disarm_at + 10 else 1.0
        rows.append((t, k % 2 if two else 0, v, a, round(used) if logged_mah else float("nan"), armed))
    return rows


def stream(rows: list[Any], values: dict[str, float], vehicle: str, variants: tuple[str, ...],
           situation: Situation, speed: float | None) -> Stream:  # fmt: skip
    """One drawn stream replayed through the Python evaluator, as data lines. ``speed`` (m/s) gives the
    distance to home of each sample (the ``distance`` variant's input), None none."""
    v = VEHICLES[vehicle]
    fs = make_failsafe(battery_settings(values, v), v, situation=situation, variants=variants)
    s = situation
    lines = [
        f"case {vehicle} {_flag(SEED_CRITICAL in variants)} {_flag(DISTANCE in variants)} {_flag(s.home_set)} "
        f"{_flag(s.position_fix)} {_flag(s.smart_rtl_ready)} {_flag(s.quadplane)} {_flag(s.landing_sequence)}"
    ]
    for i, b in fs.settings.items():
        monitor = "-" if b.monitor is None else str(b.monitor)
        lines.append(
            f"settings {i} {bits(b.capacity_mah)} {bits(b.low_volt)} {bits(b.low_timer_s)} {bits(b.low_mah)} "
            f"{bits(b.crt_volt)} {bits(b.crt_mah)} {b.low_action} {b.crt_action} {b.volt_source} {monitor}"
        )
    events = 0
    for sample in table_of(rows).samples():
        r = sample.battery
        home = None if speed is None else sample.t * speed
        lines.append(
            f"sample {round(sample.t * 1000)} {sample.instance} {_flag(sample.armed)} {bits(r.voltage_v)} "
            f"{bits(r.current_a)} {bits(r.consumed_mah)} {bits(home)}"
        )
        for event in fs.update(sample.t, r, armed=sample.armed, instance=sample.instance, distance_to_home_m=home):
            lines.append(event_line(event))
            events += 1
    lines.append("end")
    return Stream(lines, events, variants)


def collect() -> list[Stream]:
    """EXAMPLES streams, the same every run (a fixed seed): the strategies of the columnar replay's test,
    with every vehicle, the variants and the situations the fallback chains ask about; then FLIGHTS
    discharges (:func:`flight_rows`) with the same parameter sets."""
    out: list[Stream] = []

    def run(rows: st.SearchStrategy[list[Row]], examples: int) -> None:
        @settings(max_examples=examples, derandomize=False, database=None, deadline=None,
                  suppress_health_check=list(HealthCheck))  # fmt: skip
        @seed(24)
        @given(
            rows,
            VALUES,
            st.sampled_from(sorted(VEHICLES)),
            st.sampled_from(VARIANTS),
            st.builds(Situation, st.booleans(), st.booleans(), st.booleans(), st.booleans(), st.booleans()),
            st.sampled_from([None, 2.0, 8.0]),
        )
        def draw(rows: list[Row], values: dict[str, float], vehicle: str, variants: tuple[str, ...],
                 situation: Situation, speed: float | None) -> None:  # fmt: skip
            out.append(stream(rows, values, vehicle, variants, situation, speed))

        draw()

    run(st.lists(ROW, max_size=60).map(timed), EXAMPLES)
    flights = st.builds(
        flight_rows,
        st.integers(40, 300),
        st.sampled_from([50, 100, 250, 500]),
        st.floats(11.5, 12.6).map(lambda x: round(x, 2)),
        st.floats(0.005, 0.05),
        st.floats(20.0, 150.0),
        st.integers(0, 200),
        st.booleans(),
        st.booleans(),
    )
    run(flights, FLIGHTS)
    # the distance variant fires only when no capacity threshold has fired first: drawn parameter sets
    # seldom leave it the room, so these discharges do (every vehicle, charge logged or integrated)
    for k, vehicle in enumerate(sorted(VEHICLES)):
        for logged in (False, True):
            rows = flight_rows(200, 250, 12.4, 0.01, 60.0 + 20 * k, 500, k % 2 == 1, logged)
            values = {"BATT_CAPACITY": 2000.0 + 500 * k, "BATT_MONITOR": 4, "BATT_FS_LOW_ACT": 1 + k % 2}
            out.append(stream(rows, values, vehicle, (DISTANCE,), Situation(), 4.0 + 2 * k))
    return out


def write(streams: list[Stream], path: Path) -> None:
    path.write_text("".join(line + "\n" for s in streams for line in s.lines), encoding="utf-8")
