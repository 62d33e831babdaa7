"""``battgen failsafe --params FILE STREAM``: replay battery samples through the failsafe evaluator.

STREAM is JSON Lines, one sample a line (``-`` is not accepted: a file is read)::

    {"t": 0.0, "armed": true, "message": "uorb.BatteryStatus", "data": {"voltage_v": 11.9, "current_a": 2.1}}
    {"t": 1.0, "armed": true, "message": "BATTERY_STATUS", "data": {"voltages": [10400, 65535, ...]}}
    {"t": 2.0, "armed": true, "battery": {"voltage_v": 10.4, "current_a": 2.0}, "distance_to_home_m": 350}

``t`` seconds (never going back) and ``armed`` are required. The battery is a message of any
bundled format (``message`` by qualified or short name, or ``--message`` for the whole stream,
with its ``data``) or ``battery``: SI values (voltage_v, current_a, consumed_mah, remaining_mah).
Optional: ``distance_to_home_m``, ``travelled_m`` (odometer), ``home_set``, ``position_fix``.
The parameters come from a .param / .params file (BATT_* names; others ignored).

Prints one line per transition: time, level, cause, value, threshold, action and outcome, the
operator text, and the uORB ``warning`` / MAVLink ``charge_state`` values for the level.
``--json`` prints JSON Lines instead, each event with the converted message (when the sample was a
uORB battery_status or MAVLink BATTERY_STATUS) carrying the level. Exit 0 when the stream was replayed, 1 when the
parameter file holds no BATT_* parameter or the stream no sample (``--allow-empty`` accepts
either), 2 when the parameter file or the stream cannot be read.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..apps.failsafe.evaluator import BatteryFailsafe, Event
from ..apps.failsafe.levels import Level, apply_level
from ..apps.failsafe.stream import Replay, Sample, batt_parameter_count, open_reader, read_failsafe_params
from ..errors import BattgenError

EXIT_OK, EXIT_EMPTY, EXIT_UNREADABLE = 0, 1, 2


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "failsafe",
        help="replay a JSON Lines stream of battery samples through the battery failsafe",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("stream", help="JSON Lines file of battery samples")
    p.add_argument("--params", required=True, help="a .param / .params file with the BATT_* parameters")
    p.add_argument(
        "--allow-empty",
        action="store_true",
        help="a parameter file without BATT_* parameters, or a stream without samples, is not an error",
    )
    p.add_argument("--message", help="message of samples that name none (e.g. uorb.BatteryStatus)")
    p.add_argument("--schemas", help="schema folder the messages come from (default: the bundled schemas/)")
    p.add_argument("--no-home", action="store_true", help="no home position is set (RTL falls back to Hold)")
    p.add_argument("--no-fix", action="store_true", help="no position fix (RTL falls back to Hold)")
    p.add_argument("--no-smartrtl", action="store_true", help="no SmartRTL path recorded")
    p.add_argument("--margin", type=float, default=1.3, help="safety margin of the distance rule (1.3)")
    p.add_argument("--rate", type=float, help="consumption in mAh per metre until one is learned")
    p.add_argument("--json", action="store_true", help="print events as JSON Lines")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        batt, total = batt_parameter_count(Path(args.params))
        if not batt and not args.allow_empty:
            print(
                f"{args.params}: no BATT_* parameter in this file ({total} parameters read): the failsafe would run "
                "on defaults alone (--allow-empty accepts that)",
                file=sys.stderr,
            )
            return EXIT_EMPTY
        params = read_failsafe_params(Path(args.params))
        reader = open_reader(Path(args.schemas) if args.schemas else None, args.message)
        fs = BatteryFailsafe(
            params,
            home_set=not args.no_home,
            position_fix=not args.no_fix,
            smart_rtl_ready=not args.no_smartrtl,
            margin=args.margin,
            consumption_mah_per_m=args.rate,
        )
        replay = Replay(fs, reader)
        for event, sample in replay.run(Path(args.stream), args.stream):
            print(_json(event, sample) if args.json else _line(event, sample))
    except BattgenError as exc:
        print(f"battgen: {exc}", file=sys.stderr)
        return EXIT_UNREADABLE
    if not args.json:
        print(f"{replay.samples} samples, {len(fs.events)} events, final level {fs.level.name}", file=sys.stderr)
    if not replay.samples and not args.allow_empty:
        print(f"{args.stream}: no battery samples in this stream (--allow-empty accepts that)", file=sys.stderr)
        return EXIT_EMPTY
    return EXIT_OK


def _num(value: float | None, unit: str) -> str:
    if value is None:
        return "-"
    return f"{value:.0f}{unit}" if unit == "mAh" else f"{value:.2f}{unit}"


def _line(e: Event, s: Sample) -> str:
    unit = "V" if e.cause.value == "voltage" else "mAh"
    detail = (
        f"{e.level.name:<8} {e.cause.value:<9} value={_num(e.value, unit)} threshold={_num(e.threshold, unit)} "
        f"action={e.action.name} -> {e.outcome.value}"
    )
    if e.level is Level.NONE:
        detail = f"{e.level.name:<8} {e.cause.value:<9}"
    return (
        f't={e.time:10.3f}s  {detail}  "{e.text}"  uorb.warning={e.uorb_warning} '
        f"mavlink.charge_state={e.mavlink_charge_state}  (line {s.line})"
    )


def _json(e: Event, s: Sample) -> str:
    out: dict[str, Any] = {
        "t": e.time,
        "line": s.line,
        "level": e.level.name,
        "cause": e.cause.value,
        "value": e.value,
        "threshold": e.threshold,
        "action": e.action.name,
        "outcome": e.outcome.value,
        "text": e.text,
        "uorb_warning": e.uorb_warning,
        "mavlink_charge_state": e.mavlink_charge_state,
    }
    if s.message is not None and s.data is not None:
        out["message"] = s.message
        out["data"] = apply_level(s.message, s.data, e.level)
    return json.dumps(out, allow_nan=False)
