"""MAVLink telemetry logs (.tlog) as battery batches, from one CRC-checked walk over the log
(:func:`codegen.inputs.tlog.read_messages`) that reads BATTERY_STATUS, SYS_STATUS and HEARTBEAT together.

- **Batteries**: a system's BATTERY_STATUS frames, one batch per battery ``id``; a system that sends no
  BATTERY_STATUS at all is read from its SYS_STATUS frames as battery 0 (``schemas/mappings/mavlink_sys_status.yaml``).
- **Clock**: ``t`` is seconds since the log's first frame of any message (its tlog stamp); ``time_us`` is the
  record's own stamp, µs since the epoch, so ``origin_us`` is that first stamp and ``utc_offset_us`` 0. A stamp past
  int64 (a damaged entry) is unknown.
- **Armed**: as of each record in file order, ``base_mode & MAV_MODE_FLAG_SAFETY_ARMED`` of the latest vehicle
  HEARTBEAT of the record's own system; NaN before it. A heartbeat is the vehicle's unless it comes from a ground
  station (MAV_TYPE_GCS), a component that is no flight controller (MAV_AUTOPILOT_INVALID), a gimbal, ADS-B
  receiver or onboard computer: pymavlink's ``probably_vehicle_heartbeat`` rule, which a GCS shows. A system with
  no vehicle heartbeat in the log has no arming state (``armed`` None).
- **Vehicle**: ``mavlink:<system id>``, and ``vehicle_type`` the MAV_TYPE of its last vehicle heartbeat.
- **Parameters**: the system's PARAM_VALUE frames (a ground station's parameter download; a value set again: its
  last), in the context (:mod:`.context`).
- **Modes and texts**: each change of the mode its vehicle heartbeats give (``custom_mode`` named as a ground station
  names it: pymavlink's ``mode_string_v10``, PX4's main and sub mode, ArduPilot's per vehicle type), and its
  STATUSTEXT messages with their severity (a long text sent in chunks joined), in the context; the firmware the
  first ArduPilot banner among them names ("ArduPlane V3.10.0-dev (f2b4e06a)").
"""

from __future__ import annotations

import re
import struct
from array import array
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import BattgenError
from ...inputs.dataflash.log import shortest_float32
from ...inputs.model import MavlinkClass
from ...inputs.tlog import FrameRecord, StreamStats, read_messages
from .catalog import Catalog
from .context import ARMING_RULES, MAV_AUTOPILOT_FIRMWARE, SYSLOG_LEVELS, LogContext, LogText, arming_changes
from .sources import Batch, instances_to_columns, model_of

BATTERY_STATUS, SYS_STATUS, HEARTBEAT = "mavlink.BATTERY_STATUS", "mavlink.SYS_STATUS", "mavlink.HEARTBEAT"
PARAM_VALUE, STATUSTEXT = "mavlink.PARAM_VALUE", "mavlink.STATUSTEXT"
PX4_BYTEWISE = {1: "<B", 2: "<b", 3: "<H", 4: "<h", 5: "<I", 6: "<i"}  # MAV_PARAM_TYPE -> the integer in its bytes
SAFETY_ARMED = 128  # MAV_MODE_FLAG_SAFETY_ARMED
CUSTOM_MODE_ENABLED = 1  # MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
PX4_AUTOPILOT = 12  # MAV_AUTOPILOT_PX4
# the banner ArduPilot sends at boot and on a ground station's connection ("ArduPlane V4.5.7 (b0d6e8f3)")
FIRMWARE_BANNER = re.compile(r"(Ardu\w+|APM:\w+) V\d")
NOT_VEHICLE_TYPES = frozenset({6, 18, 26, 27})  # MAV_TYPE_GCS, _ONBOARD_CONTROLLER, _GIMBAL, _ADSB
AUTOPILOT_INVALID = 8  # MAV_AUTOPILOT_INVALID
COMP_GIMBAL = 154  # MAV_COMP_ID_GIMBAL


UNKNOWN_STAMP = 1 << 63  # a stamp past int64 is a damaged one, unknown (as is none): every such stamp is kept as this


@dataclass
class _Beats:
    """A system's vehicle heartbeats in file order, a column each: a tlog holds one a second for as long as it
    runs, and as tuples of Python ints they were some 200 bytes each (20 MB at 100k), here 41."""

    at: array[int] = field(default_factory=lambda: array("q"))  # the entry's offset in the file
    armed: array[int] = field(default_factory=lambda: array("b"))  # base_mode & MAV_MODE_FLAG_SAFETY_ARMED, 0/1
    mav_type: array[int] = field(default_factory=lambda: array("q"))
    stamp: array[int] = field(default_factory=lambda: array("Q"))  # the tlog stamp, or UNKNOWN_STAMP
    base_mode: array[int] = field(default_factory=lambda: array("q"))
    custom_mode: array[int] = field(default_factory=lambda: array("q"))

    def add(self, offset: int, stamp: int | None, mav_type: int, base_mode: int, custom_mode: int) -> None:
        self.at.append(offset)
        self.armed.append(1 if base_mode & SAFETY_ARMED else 0)
        self.mav_type.append(mav_type)
        self.stamp.append(UNKNOWN_STAMP if stamp is None or stamp >= UNKNOWN_STAMP else stamp)
        self.base_mode.append(base_mode)
        self.custom_mode.append(custom_mode)

    def __len__(self) -> int:
        return len(self.at)


@dataclass
class _System:
    """What one system id sent: its battery frames and its vehicle heartbeats."""

    batteries: dict[int, list[FrameRecord]] = field(default_factory=dict)
    sys_status: list[FrameRecord] = field(default_factory=list)
    beats: _Beats = field(default_factory=_Beats)
    autopilot: int | None = None  # MAV_AUTOPILOT of the last vehicle heartbeat
    parameters: dict[str, tuple[float, int]] = field(default_factory=dict)  # PARAM_VALUE: (value, MAV_PARAM_TYPE)
    texts: list[tuple[int | None, int, str, int]] = field(
        default_factory=list
    )  # STATUSTEXT (stamp, severity, text, id)
    status_only: bool = True  # no BATTERY_STATUS seen: its SYS_STATUS frames stand for battery 0


def is_vehicle_heartbeat(compid: int, mav_type: int, autopilot: int) -> bool:
    """Whether a HEARTBEAT speaks for the vehicle (see the module's docs)."""
    return compid != COMP_GIMBAL and mav_type not in NOT_VEHICLE_TYPES and autopilot != AUTOPILOT_INVALID


def _mavlink(catalog: Catalog, qualified: str) -> MavlinkClass:
    model = model_of(catalog, qualified)
    if not isinstance(model, MavlinkClass):
        raise BattgenError(f"the generated {qualified} has no MAVLink codec: run 'battgen generate'")
    return model


STREAM_ABOVE = 4 << 20  # bytes (some 60k frames): a larger tlog is walked twice, its batteries in chunks (flat memory)
CHUNK = 1 << 16  # battery frames per batch of a tlog walked twice


def tlog_batches(path: Path, name: str, catalog: Catalog) -> Iterator[Batch]:
    """Every battery of a tlog as batches (see the module's docs). A tlog of up to :data:`STREAM_ABOVE` bytes is
    walked once, each battery one batch; a larger one twice: first what the batteries' context needs (heartbeats,
    parameters, which systems send BATTERY_STATUS), then the battery frames, handed out every :data:`CHUNK`
    frames, so memory stays flat whatever the log's length. Both give the same records, clock and arming."""
    wanted = (BATTERY_STATUS, SYS_STATUS, HEARTBEAT, PARAM_VALUE, STATUSTEXT)
    models = {m.MSG_ID: m for m in (_mavlink(catalog, q) for q in wanted)}
    ids = _Ids(*(_mavlink(catalog, q).MSG_ID for q in (BATTERY_STATUS, SYS_STATUS, PARAM_VALUE, STATUSTEXT)))
    try:
        streamed = path.stat().st_size > STREAM_ABOVE
    except OSError:
        streamed = False  # the walk says why it cannot read it
    stats = StreamStats()
    systems = _survey(read_messages(path, name, models, stats), ids, keep=not streamed)
    origin = stats.first_stamp or 0
    contexts = {sysid: _context(system, sysid, origin) for sysid, system in systems.items()}
    note = stats.summary("battery") if stats.damaged else None
    if not streamed:
        for sysid, system in sorted(systems.items()):
            groups = sorted(system.batteries.items())
            if not groups and system.sys_status:
                groups = [(0, system.sys_status)]
            for instance, frames in groups:
                yield _made(catalog, ids, frames, instance, origin, system, sysid, contexts[sysid], note)
        return
    battery_models = {k: m for k, m in models.items() if k in (ids.battery, ids.status)}
    pending: dict[tuple[int, int], list[FrameRecord]] = {}
    for rec in read_messages(path, name, battery_models, StreamStats()):
        sysid = rec.frame.sysid
        owner = systems.get(sysid)
        if owner is None or (rec.frame.msgid == ids.status) != owner.status_only:
            continue  # SYS_STATUS counts only for a system that sends no BATTERY_STATUS
        instance = int(getattr(rec.instance, "id")) if rec.frame.msgid == ids.battery else 0  # noqa: B009
        frames = pending.setdefault((sysid, instance), [])
        frames.append(rec)
        if len(frames) == CHUNK:
            yield _made(catalog, ids, frames, instance, origin, owner, sysid, contexts[sysid], None)
            pending[(sysid, instance)] = []
    for (sysid, instance), frames in sorted(pending.items()):
        if frames:
            yield _made(catalog, ids, frames, instance, origin, systems[sysid], sysid, contexts[sysid], note)


@dataclass(frozen=True)
class _Ids:
    battery: int
    status: int
    param: int
    text: int


def _survey(records: Iterable[FrameRecord], ids: _Ids, *, keep: bool) -> dict[int, _System]:
    """What each system sent: heartbeats, parameters, whether it sends BATTERY_STATUS, and (``keep``) its battery
    and SYS_STATUS frames themselves."""
    systems: dict[int, _System] = {}
    for rec in records:
        system = systems.setdefault(rec.frame.sysid, _System())
        msgid = rec.frame.msgid
        if msgid == ids.battery:
            system.status_only = False
            if keep:
                system.batteries.setdefault(int(getattr(rec.instance, "id")), []).append(rec)  # noqa: B009
        elif msgid == ids.status:
            if keep:
                system.sys_status.append(rec)
        elif msgid == ids.param:
            p = rec.instance
            name = parameter_name(str(getattr(p, "param_id")))  # noqa: B009
            if name:  # a set value is sent again: the last one stands, as the vehicle ended up with it
                system.parameters[name] = (float(getattr(p, "param_value")), int(getattr(p, "param_type")))  # noqa: B009
        elif msgid == ids.text:
            m = rec.instance
            text = _text(getattr(m, "text"))  # noqa: B009
            system.texts.append((rec.timestamp, int(getattr(m, "severity")), text, int(getattr(m, "id") or 0)))  # noqa: B009
        else:
            hb = rec.instance
            mav_type, autopilot = int(getattr(hb, "type")), int(getattr(hb, "autopilot"))  # noqa: B009
            if is_vehicle_heartbeat(rec.frame.compid, mav_type, autopilot):
                base_mode, custom_mode = int(getattr(hb, "base_mode")), int(getattr(hb, "custom_mode"))  # noqa: B009
                system.beats.add(rec.offset or 0, rec.timestamp, mav_type, base_mode, custom_mode)
                system.autopilot = autopilot
    return systems


def _made(
    catalog: Catalog,
    ids: _Ids,
    frames: list[FrameRecord],
    instance: int,
    origin: int,
    system: _System,
    sysid: int,
    context: LogContext,
    note: str | None,
) -> Batch:
    qualified = BATTERY_STATUS if frames[0].frame.msgid == ids.battery else SYS_STATUS
    batch = _batch(catalog, qualified, frames, instance, origin, system, sysid)
    batch.context = context
    if note:
        batch.notes.append(note)
    return batch


def _batch(
    catalog: Catalog, qualified: str, frames: list[FrameRecord], instance: int, origin: int, system: _System, sysid: int
) -> Batch:
    n = len(frames)
    known = np.array([f.timestamp is not None and f.timestamp < 1 << 63 for f in frames], bool)
    stamps = np.array([f.timestamp if ok else 0 for f, ok in zip(frames, known, strict=True)], np.int64)
    batch = Batch(
        qualified,
        n,
        instances_to_columns(catalog.schema.message(qualified), [f.instance for f in frames]),
        np.where(known, (stamps - origin) / 1e6, np.nan),
        np.full(n, instance, np.int64),
        time_us=stamps,
        time_known=None if known.all() else known,
        vehicle=f"mavlink:{sysid}",
    )
    batch.origin_us, batch.utc_offset_us = origin, 0
    if len(system.beats):
        beat_at = np.frombuffer(system.beats.at, np.int64)
        beat_armed = np.frombuffer(system.beats.armed, np.int8).astype(np.float64)
        at = np.array([f.offset or 0 for f in frames], np.int64)
        idx = np.searchsorted(beat_at, at, side="right") - 1  # the latest heartbeat before the record in the file
        batch.armed = np.where(idx >= 0, beat_armed[np.maximum(idx, 0)], np.nan)
        batch.vehicle_type = system.beats.mav_type[-1]
    return batch


def _context(system: _System, sysid: int, origin: int) -> LogContext:
    """One system's context (:mod:`.context`): its id, MAV_TYPE, firmware family and arming changes."""
    beats = system.beats
    if not len(beats):
        return LogContext("tlog", origin, 0, f"mavlink:{sysid}", parameters=_parameters(system, None))
    known = [(s, a) for s, a in zip(beats.stamp, beats.armed, strict=True) if s < UNKNOWN_STAMP]
    t = np.array([(s - origin) / 1e6 for s, _ in known], np.float64)
    armed = np.array([a for _, a in known], np.float64)
    autopilot = MAV_AUTOPILOT_FIRMWARE.get(system.autopilot) if system.autopilot is not None else None
    texts = _texts(system, origin)
    return LogContext(
        "tlog",
        origin,
        0,
        f"mavlink:{sysid}",
        beats.mav_type[-1],
        autopilot,
        parameters=_parameters(system, autopilot),
        arming=arming_changes(t, armed),
        arming_rule=ARMING_RULES["tlog"],
        firmware=next((x.text for x in texts if FIRMWARE_BANNER.match(x.text)), None),
        texts=texts,
        modes=_modes(system, origin),
    )


def _seconds(stamp: int | None, origin: int) -> float | None:
    return None if stamp is None or stamp >= 1 << 63 else (stamp - origin) / 1e6


def _text(value: object) -> str:
    """A STATUSTEXT's text up to its NUL (the field may hold bytes or text)."""
    if isinstance(value, bytes | bytearray):
        value = bytes(value).split(b"\x00", 1)[0].decode("utf-8", "replace")
    return str(value).split("\x00", 1)[0]


def _texts(system: _System, origin: int) -> tuple[LogText, ...]:
    """The system's STATUSTEXTs in order; the chunks of one long text (the same nonzero id, in a row) joined."""
    out: list[LogText] = []
    last_id = 0
    for stamp, severity, text, text_id in system.texts:
        t = _seconds(stamp, origin)
        if t is None:
            continue
        level = SYSLOG_LEVELS[severity] if 0 <= severity < len(SYSLOG_LEVELS) else f"severity {severity}"
        if text_id and text_id == last_id and out:
            out[-1] = LogText(out[-1].t, out[-1].severity, out[-1].text + text)
        else:
            out.append(LogText(t, level, text))
        last_id = text_id
    return tuple(out)


def _modes(system: _System, origin: int) -> tuple[tuple[float, str], ...]:
    """Each change of the mode the vehicle heartbeats give, named as a ground station names it."""
    from pymavlink import mavutil  # the tlog reader's reference, already a dependency

    out: list[tuple[float, str]] = []
    last: str | None = None
    beats = system.beats
    for stamp, mav_type, base, custom in zip(
        beats.stamp, beats.mav_type, beats.base_mode, beats.custom_mode, strict=True
    ):
        t = _seconds(stamp, origin)
        if t is None:
            continue
        name = mode_name(mavutil, base, custom, mav_type, system.autopilot)
        if name != last:
            out.append((t, name))
            last = name
    return tuple(out)


def mode_name(mavutil: Any, base_mode: int, custom_mode: int, mav_type: int, autopilot: int | None) -> str:
    """pymavlink's ``mode_string_v10`` for a heartbeat's fields: PX4's main and sub mode, else the vehicle
    type's mode table (ArduPilot's), else ``Mode(N)``."""
    if autopilot == PX4_AUTOPILOT:
        return str(mavutil.interpret_px4_mode(base_mode, custom_mode))
    if not base_mode & CUSTOM_MODE_ENABLED:
        return f"Mode(0x{base_mode:08x})"
    names = mavutil.mode_mapping_bynumber(mav_type) or {}
    return str(names[custom_mode]) if custom_mode in names else f"Mode({custom_mode})"


def parameter_name(param_id: str) -> str:
    """A PARAM_VALUE's name up to its first character that is not printable ASCII: the firmware's names are ASCII
    (at most 16, NUL-terminated when shorter), and older firmware left a byte of an earlier name after a short one."""
    for k, c in enumerate(param_id):
        if not (" " < c <= "~"):
            return param_id[:k]
    return param_id


def _parameters(system: _System, autopilot: str | None) -> dict[str, float]:
    """A system's PARAM_VALUE values: ArduPilot sends the number itself (a float32, taken as its shortest
    decimal); PX4 encodes an integer parameter bytewise, its bytes in the float's."""
    out: dict[str, float] = {}
    for name, (value, kind) in system.parameters.items():
        fmt = PX4_BYTEWISE.get(kind) if autopilot == "px4" else None
        if fmt is not None:
            raw = struct.pack("<f", value)
            out[name] = float(struct.unpack_from(fmt, raw)[0])
        else:
            out[name] = shortest_float32(value)  # NaN, infinities and integers come back as they are
    return out
