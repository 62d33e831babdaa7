"""``battgen failsafe [--firmware px4|ardupilot] [--params FILE] [--vehicle NAME] STREAM``: replay batteries through
an autopilot's battery failsafe, PX4's or ArduPilot's.

The firmware is ``--firmware``; else that of the given parameters (ArduPilot's BATT*_ or PX4's BAT_*/COM_*); else
the log's own (its context: a ULog is PX4's, a DataFlash log ArduPilot's, a tlog's heartbeats name it); a JSON Lines
stream is replayed through ArduPilot's. Both print their events in one format.

PX4 (a ULog): each battery's logged state of charge through PX4's warning levels (BAT_LOW_THR, BAT_CRIT_THR,
BAT_EMERGEN_THR), commander's failsafe warning and its action (COM_LOW_BAT_ACT, COM_FAIL_ACT_T), with the log's own
parameters (``--params`` on top), and the replay checked against what the firmware logged (battery_status.warning,
failsafe_flags.battery_warning, vehicle_status.nav_state): one ``check`` line each on stderr, ``--strict`` makes a
check that fails exit 3. An ArduPilot DataFlash log is checked the same way against its ERR (subsystem 6) and MODE
(reason 4) records.

ArduPilot:

STREAM is a flight log or capture, or a JSON Lines file of samples, told apart by content (then extension).
A log (PX4 ULog, MAVLink tlog, ArduPilot DataFlash binary or text, CAN capture) is read through the battery
view ``export`` and ``report`` read too (``codegen.apps.battery``): the same records, clock (seconds since the
log's start), battery numbers and arming state (a Cyphal/CAN capture's UDRAL batteries with ``--cyphal-subject
ID=TYPE``, as ``export`` reads them); an ArduPilot log's own parameters (a DataFlash log's PARM records,
a tlog's PARAM_VALUE frames) are the parameters when ``--params`` is not given. A JSON Lines stream holds one
sample a line::

    {"t": 0.0, "armed": true, "message": "uorb.BatteryStatus", "data": {"voltage_v": 11.9, "current_a": 2.1}}
    {"t": 1.0, "armed": true, "instance": 2, "battery": {"voltage_v": 10.4, "current_a": 2.0}}

  ``t`` seconds (never going back) and ``armed`` are required; ``instance`` is the battery (1-based,
  default: the message's id, else 1). The battery is a message of any bundled format (``message``, or
  ``--message`` for the whole stream, with its ``data``) or ``battery``: SI values (voltage_v,
  current_a, consumed_mah, remaining_mah). Optional: ``distance_to_home_m``, ``travelled_m``,
  ``home_set``, ``position_fix``.

The parameters (``--params``: ArduPilot .param/.parm/.params, QGroundControl .params) give every
battery's BATT_, BATT2_ .. BATT9_, BATTA_ .. BATTG_ settings. The vehicle (``--vehicle``) decides
what an action code means, its priority and its fallbacks; without it, it is detected from
parameters only one vehicle has, else rover is assumed (said on stderr either way).

Semantics are ArduPilot's AP_BattMonitor (see docs/failsafe.md); ``--variant
seed-critical`` and ``--variant distance`` turn on the seed's own choices. Prints one line per
transition (``--json``: one JSON object per line). Exit 0; 1 when the parameters hold no BATT*_
one or the input no battery reading (``--allow-empty`` accepts both); 2 when an input cannot be read; 3 with
``--strict`` when a replay does not reproduce what the log recorded.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..apps.failsafe.distance import DistanceRule
from ..apps.failsafe.evaluator import VARIANTS, Event, make_failsafe
from ..apps.failsafe.firmware import FIRMWARES, choose_firmware
from ..apps.failsafe.legacy_parameters import renamed, with_current_names
from ..apps.failsafe.levels import apply_level
from ..apps.failsafe.settings import battery_settings
from ..apps.failsafe.stream import Replay, Sample, batt_parameter_count, open_reader, read_parameter_values
from ..apps.failsafe.vehicles import VEHICLES, Situation, detect_vehicle
from ..errors import BattgenError, missing_file
from ..inputs.parameters import files as parameter_files
from ..text.escape import line
from .cyphal_options import add_cyphal_subject, check_bundled_subjects

# The flight logs' readers (numpy, pymavlink, python-can, the IR) are imported when the input is a log: a JSON
# Lines stream of samples is replayed without them, and its start-up is most of what a short stream costs.
if TYPE_CHECKING:
    from ..apps.failsafe.logs import SampleTable
    from ..apps.failsafe.px4_replay import Px4Event

EXIT_OK, EXIT_EMPTY, EXIT_UNREADABLE, EXIT_DIFFERS = 0, 1, 2, 3


def register(subparsers: Any, summary: str) -> None:
    p = subparsers.add_parser(
        "failsafe",
        help=summary,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("stream", help=".ulg, .tlog, .bin or a JSON Lines file of battery samples")
    p.add_argument("--firmware", choices=FIRMWARES, help="whose failsafe (default: the parameters', else the log's)")
    p.add_argument("--params", help="parameter file (ArduPilot BATT*_ or PX4 BAT_*/COM_*; else the log's own)")
    p.add_argument("--strict", action="store_true", help="exit 3 when the replay differs from what the log recorded")
    p.add_argument("--vehicle", choices=sorted(VEHICLES), help="ArduPilot vehicle (default: detected, else rover)")
    p.add_argument("--variant", action="append", choices=sorted(VARIANTS), default=[], help="a seed variant (opt-in)")
    p.add_argument(
        "--allow-empty",
        action="store_true",
        help="parameters without any BATT*_ one, or an input without battery readings, are not an error",
    )
    p.add_argument("--message", help="message of samples that name none (e.g. uorb.BatteryStatus)")
    add_cyphal_subject(p)
    p.add_argument("--schemas", help="schema folder the messages come from (default: the bundled schemas/)")
    p.add_argument("--no-home", action="store_true", help="no home position is set (RTL falls back)")
    p.add_argument("--no-fix", action="store_true", help="no position fix (RTL falls back)")
    p.add_argument("--no-smartrtl", action="store_true", help="no SmartRTL path recorded")
    p.add_argument("--quadplane", choices=("yes", "no"), help="plane: a QuadPlane is available (default: Q_ENABLE)")
    p.add_argument("--landing-sequence", action="store_true", help="the mission holds a DO_LAND_START sequence")
    p.add_argument("--margin", type=float, default=1.3, help="distance variant: safety margin (1.3)")
    p.add_argument("--rate", type=float, help="distance variant: consumption in mAh per metre until one is learned")
    p.add_argument("--json", action="store_true", help="print events as JSON Lines")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    stream = Path(args.stream)
    for given in (args.stream, args.params):  # before anything asks for what a missing file would have held
        if given is not None and given != "-" and not Path(given).is_file():
            raise missing_file(given)
    try:
        given = read_parameter_values(Path(args.params)) if args.params else None
        check_bundled_subjects(args.cyphal_subject)  # a wrong ID=TYPE pair said once, before the log is read
        firmware, how = choose_firmware(args.firmware, given, args.params or "", stream)
    except (BattgenError, ValueError) as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    if firmware == "px4":
        return _run_px4(args, stream, how, given or {})
    try:
        # a flight log or capture is read through the battery view; JSON and JSON Lines are sample streams
        table: SampleTable | None = None
        if _is_flight_log(stream):
            from ..apps.failsafe.logs import log_samples

            table = log_samples(stream, args.stream, args.cyphal_subject)
        if table is not None and table.empty:  # said before the parameters a log without batteries may also lack
            return _no_readings(args)
        own = None
        if table is not None and not args.params:
            from ..apps.failsafe.logs import own_parameters

            own = own_parameters(table)
        raw: Mapping[str, float] = {}
        if args.params:
            raw = read_parameter_values(Path(args.params))
            values: dict[str, float] = with_current_names(raw)
            where = args.params
            for repeat in parameter_files.repeats(parameter_files.load(Path(args.params))):
                print(line(f"battgen: warning: {args.params}:{repeat.lines[-1]}: {repeat.message()}"), file=sys.stderr)
        elif own is not None and table is not None and table.context is not None:
            raw = table.context.parameters
            values, where = own, f"{args.stream} ({table.context.parameters_from})"
        else:
            raise BattgenError(f"expected --params FILE: {_why_no_parameters(table)}")
        for old in renamed(raw):  # an older firmware's names, replayed under today's
            print(line(f"battgen: warning: {where}: {old.message()}"), file=sys.stderr)
        if args.params and not batt_parameter_count(values) and not args.allow_empty:
            print(
                line(
                    f"{where}: no BATT*_ parameter ({len(values)} parameters read): the failsafe would run on "
                    "defaults alone (--allow-empty accepts that)"
                ),
                file=sys.stderr,
            )
            return EXIT_EMPTY
        detection = detect_vehicle(values, args.vehicle)
        vehicle = detection.vehicle
        settings = battery_settings(values, vehicle)
        quadplane = args.quadplane == "yes" if args.quadplane else values.get("Q_ENABLE", 0) == 1
        situation = Situation(
            home_set=not args.no_home,
            position_fix=not args.no_fix,
            smart_rtl_ready=not args.no_smartrtl,
            quadplane=quadplane,
            landing_sequence=args.landing_sequence,
        )
        fs = make_failsafe(
            settings,
            vehicle,
            situation=situation,
            variants=args.variant,
            distance_rule=DistanceRule(margin=args.margin, consumption_mah_per_m=args.rate),
        )
        print(line(f"battgen: vehicle {detection.how}; parameters from {where}"), file=sys.stderr)
        for variant in args.variant:
            print(line(f"battgen: variant {variant}: {VARIANTS[variant]}"), file=sys.stderr)
        reader = open_reader(Path(args.schemas) if args.schemas else None, args.message)
        replay = Replay(fs, reader)
        if table is not None and not table.has_arming:
            from ..apps.failsafe.logs import NO_ARMING_NOTE

            print(line(f"battgen: {args.stream}: {NO_ARMING_NOTE}"), file=sys.stderr)
        events: Iterable[tuple[Event, Sample]]
        read = 0
        if table is not None:  # a log: replayed over its columns (the same events as sample by sample)
            from ..apps.failsafe.columnar import replay_table

            events, counts = replay_table(fs, table, args.stream)
            read = sum(counts.values())
        else:
            events = replay.run(stream, args.stream)
        for event, sample in events:
            print(_json(event, sample, vehicle.name) if args.json else line(_line(event, sample)))
        read = replay.samples if table is None else read
        if read == 0:  # a readable input without battery readings: exit 1 like every command (README)
            return _no_readings(args)
        checks = []
        if table is not None:
            from ..apps.failsafe.ardupilot_logged import check_log

            checks = check_log(stream, args.stream, table, fs.events)
        for check in checks:
            print(line(f"battgen: check {check.what}: {check.verdict()}"), file=sys.stderr)
    except (BattgenError, ValueError) as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    print(line(f"{read} samples, {len(fs.events)} events, final level {fs.level.name}"), file=sys.stderr)
    return EXIT_DIFFERS if args.strict and any(c.problems for c in checks) else EXIT_OK


def _is_flight_log(stream: Path) -> bool:
    """Whether the input is a flight log or capture (else a stream of samples), told by content, then extension."""
    from ..inputs.files.kinds import FLIGHT_LOG_KINDS, detect  # brings the IR's formats: asked once per run

    return detect(stream) in FLIGHT_LOG_KINDS


def _run_px4(args: argparse.Namespace, stream: Path, how: str, given: dict[str, float]) -> int:
    from ..apps.failsafe.px4_log import NoBatteryRecords, read_px4_log
    from ..apps.failsafe.px4_replay import replay_px4
    from ..inputs.files.kinds import detect

    try:
        if detect(stream) != "ulog":
            raise BattgenError(
                f"{args.stream}: expected a PX4 ULog (.ulg): PX4's replay starts from the battery_status the firmware "
                "logged"
            )
        log = read_px4_log(stream, args.stream)
        replay = replay_px4(log, given)
    except NoBatteryRecords:
        return _no_readings(args)
    except (BattgenError, ValueError) as exc:
        print(line(f"battgen: {exc}"), file=sys.stderr)
        return EXIT_UNREADABLE
    if replay.samples == 0:  # a readable ULog without battery_status: exit 1, as for ArduPilot's replay
        return _no_readings(args)
    where = f"{args.params} over the log's PARAM definitions" if args.params else f"{args.stream} (PARAM definitions)"
    thr, st = replay.thresholds, replay.settings
    print(line(f"battgen: firmware px4 ({how}; {log.context.firmware or 'release unknown'}); parameters from {where}: "
               f"BAT_LOW_THR {thr.low:g} BAT_CRIT_THR {thr.critical:g} BAT_EMERGEN_THR {thr.emergency:g} "
               f"COM_LOW_BAT_ACT {st.low_bat_act} COM_FAIL_ACT_T {st.fail_act_t:g}"), file=sys.stderr)  # fmt: skip
    if args.vehicle or args.variant:
        print("battgen: warning: --vehicle and --variant are ArduPilot's: not used for PX4", file=sys.stderr)
    for note in replay.notes:
        print(line(f"battgen: note: {note}"), file=sys.stderr)
    for event in replay.events:
        print(_px4_json(event) if args.json else line(_px4_line(event)))
    for check in replay.checks:
        print(line(f"battgen: check {check.what}: {check.verdict()}"), file=sys.stderr)
    level = max((e.level for e in replay.events if e.cause == "charge"), default=None)
    print(line(f"{replay.samples} samples, {len(replay.events)} events, final level {level.name if level else 'NONE'}"),
          file=sys.stderr)  # fmt: skip
    return EXIT_DIFFERS if args.strict and any(c.problems for c in replay.checks) else EXIT_OK


def _no_readings(args: argparse.Namespace) -> int:
    """A readable input without battery readings: exit 1, or 0 with ``--allow-empty``."""
    if args.allow_empty:
        print(line(f"{args.stream}: no battery readings"), file=sys.stderr)
        return EXIT_OK
    print(line(f"{args.stream}: expected battery readings, found none (--allow-empty accepts that)"), file=sys.stderr)
    return EXIT_EMPTY


def _px4_line(e: Px4Event) -> str:
    return (
        f"t={e.time:10.3f}s  battery {e.battery} {e.label:<8} {e.cause:<8} value={e.value:.3f} "
        f"threshold={e.threshold:.3f} action={e.action_name} ({e.action_code}) -> {e.outcome}  "
        f'"{e.text}"  uorb.warning={int(e.level)}  ({e.place})'
    )


def _px4_json(e: Px4Event) -> str:
    out: dict[str, Any] = {
        "t": e.time,
        "battery": e.battery,
        "level": e.label,
        "cause": e.cause,
        "value": e.value if e.value == e.value else None,
        "threshold": e.threshold,
        "action": e.action_name,
        "action_code": e.action_code,
        "executed": True,
        "outcome": e.outcome,
        "firmware": "px4",
        "firmware_text": e.text,
        "uorb_warning": int(e.level),
        "where": e.place,
    }
    return json.dumps(out, allow_nan=False)


def _why_no_parameters(table: SampleTable | None) -> str:
    """Why a stream brings no ArduPilot parameters of its own."""
    context = table.context if table is not None else None
    if context is not None and context.autopilot == "px4":
        return (
            f"this is a PX4 log ({len(context.parameters)} PX4 parameters, such as BAT_LOW_THR); ArduPilot's "
            "failsafe needs BATT_* values, and PX4's replay reads a ULog (its battery_status)"
        )
    return "the input carries no ArduPilot parameters of its own (a DataFlash log's PARM, a tlog's PARAM_VALUE)"


def _num(value: float, unit: str) -> str:
    return f"{value:.0f}{unit}" if unit == "mAh" else f"{value:.2f}{unit}"


def _line(e: Event, s: Sample) -> str:
    unit = "V" if e.cause == "voltage" else "mAh"
    run_ = f"-> {e.outcome}" if e.executed else f"not run (priority {e.priority} is below one already run)"
    return (
        f"t={e.time:10.3f}s  battery {e.battery} {e.level.name:<8} {e.cause:<8} value={_num(e.value, unit)} "
        f"threshold={_num(e.threshold, unit)} action={e.action} ({e.action_code}) {run_}  "
        f'"{e.ardupilot_text}"  seed: "{e.text}"  uorb.warning={e.uorb_warning} '
        f"mavlink.charge_state={e.mavlink_charge_state}  ({s.place})"
    )


def _json(e: Event, s: Sample, vehicle: str) -> str:
    out: dict[str, Any] = {
        "t": e.time,
        "battery": e.battery,
        "level": e.level.name,
        "cause": e.cause,
        "value": e.value,
        "threshold": e.threshold,
        "action": e.action,
        "action_code": e.action_code,
        "executed": e.executed,
        "outcome": e.outcome,
        "priority": e.priority,
        "vehicle": vehicle,
        "voltage_source": e.voltage_source,
        "seed_text": e.text,
        "ardupilot_text": e.ardupilot_text,
        "uorb_warning": e.uorb_warning,
        "mavlink_charge_state": e.mavlink_charge_state,
        "where": s.place,
        "firmware": "ardupilot",
        "firmware_text": e.ardupilot_text,
    }
    if s.message is not None and s.data is not None:
        out["message"] = s.message
        out["data"] = apply_level(s.message, s.data, e.level)
    return json.dumps(out, allow_nan=False)
