"""A PX4 log replayed through PX4's battery failsafe (:mod:`.px4_levels`, :mod:`.px4_actions`), and the replay
checked against what the firmware logged.

The replay starts from each battery's logged state of charge (``battery_status.remaining``: the firmware's own
estimate, which its warning was computed from; re-estimating it from voltage and current is another model) and the
log's own parameters (``BAT_LOW_THR`` .. ``COM_FAIL_ACT_T``, any given ones on top; absent ones at PX4's defaults):

1. each battery's warning per update (``Battery::updateBatteryStatus``);
2. commander's failsafe warning at each battery update (``BatteryChecks::checkAndReport``), with the arming state of
   the battery view;
3. an event where that warning rises while armed, or is above NONE when the vehicle arms, with commander's action
   (``Failsafe::checkStateAndMode``).

The checks compare each with the log: the battery's logged ``warning`` (same level, same sample or the next), the
logged ``failsafe_flags.battery_warning`` (same level, within one sample of either topic: commander logs at its own
rate) and, for a mode action, ``vehicle_status.nav_state`` reaching the action's mode (after the Hold of
``COM_FAIL_ACT_T``). Where the log does not record what a check needs, the check says so instead of passing.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..battery.columns import NDArray
from ..battery.sources import as_of
from .px4_actions import (
    FLIGHT_TIME_TEXT,
    FLTT_ACTIONS,
    LOW_BAT_ACTIONS,
    NAV_STATES,
    TEXTS,
    Action,
    Px4Settings,
    acting_parameter,
    arming_refused,
    battery_action,
    flight_time_action,
    remaining_time_flags,
)
from .px4_levels import Px4Level, Thresholds, battery_warnings, commander_warning, latches, release_of
from .px4_log import Px4Log
from .replay_checks import Change, Check, changes, interval, within_one_sample

FRAMEWORK_FROM = (1, 14)  # failsafe_flags and the failsafe framework (src/modules/commander/failsafe/)


@dataclass(frozen=True)
class Px4Event:
    """A rise of commander's battery warning while armed (``cause`` "charge"), or of its remaining-flight-time
    condition (``cause`` "time": value and threshold in seconds), and what commander does about it."""

    time: float
    battery: int  # the battery whose warning is the worst, or whose time is the shortest (1-based)
    level: Px4Level  # NONE for a remaining-flight-time event
    value: float  # that battery's state of charge (its time_remaining_s)
    threshold: float  # the threshold it is below (the RTL estimate's safe time)
    action_code: (
        int  # the COM_LOW_BAT_ACT in effect (0 where the at-arming rule makes it a warning), or COM_FLTT_LOW_ACT
    )
    action: Action
    delay_s: float  # the Hold before a mode action (COM_FAIL_ACT_T)
    text: str  # the operator's notification (framework.cpp notifyUser)
    place: str
    cause: str = "charge"

    @property
    def label(self) -> str:
        return self.level.name if self.cause == "charge" else "TIME_LOW"

    @property
    def action_name(self) -> str:
        names = LOW_BAT_ACTIONS if self.cause == "charge" else FLTT_ACTIONS
        return names.get(self.action_code, f"unknown ({self.action_code})")

    @property
    def outcome(self) -> str:
        name = self.action.name.lower()
        if self.action in (Action.RTL, Action.LAND) and self.delay_s > 0:
            return f"hold {self.delay_s:g}s, then {name}"
        return name


@dataclass
class Px4Replay:
    release: tuple[int, int, int] | None
    thresholds: Thresholds
    settings: Px4Settings
    events: list[Px4Event]
    checks: list[Check]
    samples: int
    readings: dict[int, int]  # the updates replayed per battery (1-based)

    @property
    def notes(self) -> list[str]:
        """What the replay takes on trust for this log's release."""
        if self.release is not None and self.release[:2] < FRAMEWORK_FROM:
            version = ".".join(map(str, self.release))
            return [
                f"PX4 v{version} predates the failsafe framework (v1.14): commander's reaction is replayed with its "
                "rules (the actions per level are the same; the texts and the Hold before an action may differ)"
            ]
        return []


def replay_px4(log: Px4Log, given: Mapping[str, float] | None = None) -> Px4Replay:
    """Replay a log (:func:`.px4_log.read_px4_log`) with its parameters, ``given`` ones on top (a ValueError names a
    parameter that is no number)."""
    values = {**log.context.parameters, **(given or {})}
    thresholds, settings = Thresholds.from_values(values), Px4Settings.from_values(values)
    release = release_of(log.context.firmware)
    per_battery: list[tuple[NDArray, NDArray, NDArray]] = []
    checks: list[Check] = []
    for b in log.batteries:
        warnings = battery_warnings(b.boot_s, b.remaining, b.connected, thresholds, latched=latches(release))
        per_battery.append((b.t, warnings, b.connected))
        checks.append(_battery_check(b.battery, b.t, b.warning, warnings))
    t = np.unique(np.concatenate([b.t for b in log.batteries])) if log.batteries else np.zeros(0)
    armed = _armed_at(log, t)
    flag = commander_warning(per_battery, t, armed)
    events = _events(log, t, armed, flag, per_battery, thresholds, settings, release)
    checks.append(_commander_check(log, t, flag, release))
    checks.append(_arming_check(log, t, flag, values.get("COM_ARM_BAT_MIN"), release))
    time_events, time_check = _remaining_time(log, settings, release)
    events = sorted(events + time_events, key=lambda e: e.time)
    checks.append(time_check)
    checks.extend(_action_checks(log, events))
    readings = {b.battery: len(b.t) for b in log.batteries}
    return Px4Replay(release, thresholds, settings, events, checks, sum(readings.values()), readings)


def _armed_at(log: Px4Log, t: NDArray) -> NDArray:
    arming = log.context.arming
    if not arming:
        return np.zeros(len(t), bool)
    times = np.array([a[0] for a in arming], np.float64)
    states = np.array([1.0 if a[1] else 0.0 for a in arming])
    return np.asarray(np.nan_to_num(as_of(times, states, t)) == 1.0)


def _events(
    log: Px4Log,
    t: NDArray,
    armed: NDArray,
    flag: NDArray,
    per_battery: list[tuple[NDArray, NDArray, NDArray]],
    thresholds: Thresholds,
    settings: Px4Settings,
    release: tuple[int, int, int] | None,
) -> list[Px4Event]:
    out: list[Px4Event] = []
    n = len(t)
    if not n:
        return out
    # over the columns: an event where the warning rises while armed, or is above NONE as the vehicle arms; the
    # warning as of the arming (Failsafe::updateArmingState) is the one at the start of the armed run
    armed_b = np.asarray(armed, bool)
    was_armed = np.concatenate(([False], armed_b[:-1]))
    rises = np.empty(n, bool)
    rises[0] = flag[0] > 0
    rises[1:] = flag[1:] > flag[:-1]
    at = np.arange(n)
    arming = np.maximum.accumulate(np.where(armed_b & ~was_armed, at, 0))
    fires = np.flatnonzero(armed_b & (flag > 0) & (rises | ~was_armed))
    levels, armings = flag[fires].tolist(), flag[arming[fires]].tolist()
    for tk, fk, ak in zip(t[fires].tolist(), levels, armings, strict=True):
        level, at_arming = Px4Level(fk), Px4Level(ak)
        code = acting_parameter(settings.low_bat_act, level, at_arming, release)
        action = battery_action(code, level)
        battery, value, row = _worst(log, per_battery, tk, level)
        out.append(
            Px4Event(
                tk,
                battery,
                level,
                value,
                thresholds.threshold(level),
                code,
                action,
                settings.delay_s if action in (Action.RTL, Action.LAND) else 0.0,
                TEXTS[level],
                f"battery_status record {row} of battery {battery}",
            )
        )
    return out


def _arming_check(
    log: Px4Log, t: NDArray, flag: NDArray, arm_bat_min: float | None, release: tuple[int, int, int] | None
) -> Check:
    """Each arming the log records against the battery check's arming rule, with the level as of that moment."""
    armings = [ta for ta, on in log.context.arming if on]
    check = Check("arming with the battery's level", [Change(ta, 1) for ta in armings], [])
    if release is not None and release[:2] < FRAMEWORK_FROM:
        check.undecided = "the release predates the health and arming checks (v1.14) the replay follows"
        return check
    unknown = 0
    for ta in armings:
        k = int(np.searchsorted(t, ta, side="right")) - 1
        if k < 0:
            unknown += 1
            continue
        level, worst = Px4Level(int(flag[k])), _worst_remaining(log, ta)
        if arming_refused(level, worst, arm_bat_min, release):
            check.problems.append(f"armed at {ta:.3f}s with {level.name}, {worst:.3f} left: the battery check refuses")
        else:
            check.replayed.append(Change(ta, 1))
    if armings and unknown == len(armings):
        check.undecided = "the log has no battery update before its armings"
    return check


def _worst_remaining(log: Px4Log, t: float) -> float:
    """The lowest state of charge of the connected batteries as of ``t`` (1 where none: checkAndReport's start)."""
    worst = 1.0
    for b in log.batteries:
        k = int(np.searchsorted(b.t, t, side="right")) - 1
        if k >= 0 and b.connected[k] and b.remaining[k] < worst:
            worst = float(b.remaining[k])
    return worst


def _remaining_time(
    log: Px4Log, settings: Px4Settings, release: tuple[int, int, int] | None
) -> tuple[list[Px4Event], Check]:
    """The remaining-flight-time failsafe at every battery update and RTL estimate, and its check."""
    what = "failsafe_flags.battery_low_remaining_time"
    if release is not None and release[:2] < FRAMEWORK_FROM:
        why = "the release predates the failsafe framework (v1.14) the replay follows"
        return [], Check(what, [], [], undecided=why)
    if log.rtl_safe_time is None:
        return [], Check(what, [], [], undecided="the log has no rtl_time_estimate to compare the time left with")
    est = log.rtl_safe_time
    t = np.unique(np.concatenate([est.t, *(b.t for b in log.batteries)]))
    armed = _armed_at(log, t)
    per_battery = [(b.t, b.time_remaining, b.connected) for b in log.batteries]
    flags = remaining_time_flags(t, (est.t, est.values), per_battery, armed).astype(np.int64)
    got = changes(t, flags)
    action = flight_time_action(settings.fltt_low_act)
    events = []
    for change in got:
        if change.value and action is not Action.NONE:
            battery, left = _shortest(log, change.t)
            k = int(np.searchsorted(est.t, change.t, side="right")) - 1
            delay = settings.delay_s if action is Action.RTL else 0.0
            place = f"rtl_time_estimate record {k}"
            code, safe = settings.fltt_low_act, float(est.values[k])
            events.append(Px4Event(change.t, battery, Px4Level.NONE, left, safe, code, action, delay,
                                   FLIGHT_TIME_TEXT, place, "time"))  # fmt: skip
    if log.low_remaining_time is None:
        return events, Check(what, [], got, undecided="the log does not record failsafe_flags")
    want = changes(log.low_remaining_time.t, log.low_remaining_time.values)
    check = Check(what, want, got)
    check.problems = within_one_sample(want, got, [log.low_remaining_time.t, t])
    return events, check


def _shortest(log: Px4Log, t: float) -> tuple[int, float]:
    """The battery with the least time remaining as of ``t``, and that time."""
    best = (log.batteries[0].battery, float("nan"))
    for b in log.batteries:
        k = int(np.searchsorted(b.t, t, side="right")) - 1
        left = float(b.time_remaining[k]) if k >= 0 else float("nan")
        if left == left and not best[1] <= left:
            best = (b.battery, left)
    return best


def _worst(
    log: Px4Log, per_battery: list[tuple[NDArray, NDArray, NDArray]], t: float, level: Px4Level
) -> tuple[int, float, int]:
    """The battery at ``level`` as of ``t``, its state of charge and the index of its record."""
    for b, (times, warnings, _) in zip(log.batteries, per_battery, strict=True):
        k = int(np.searchsorted(times, t, side="right")) - 1
        if k >= 0 and warnings[k] == level:
            return b.battery, float(b.remaining[k]), k
    return log.batteries[0].battery, float("nan"), -1


def _battery_check(battery: int, t: NDArray, logged: NDArray, replayed: NDArray) -> Check:
    what = f"battery {battery} battery_status.warning"
    want, got = changes(t, logged, skip=-1), changes(t, replayed)
    check = Check(what, want, got)
    if (logged < 0).all():
        check.undecided = "the log's battery_status has no warning"
    else:
        check.problems = within_one_sample(want, got, [t])
    return check


def _commander_check(log: Px4Log, t: NDArray, flag: NDArray, release: tuple[int, int, int] | None) -> Check:
    got = changes(t, flag)
    topic = log.failsafe_warning
    if topic is None:
        check = Check("failsafe_flags.battery_warning", [], got)
        era = "before v1.14" if release is not None and release[:2] < FRAMEWORK_FROM else "not in this log"
        check.undecided = f"the log does not record failsafe_flags ({era})"
        return check
    want = changes(topic.t, topic.values)
    check = Check("failsafe_flags.battery_warning", want, got)
    check.problems = within_one_sample(want, got, [topic.t, t])
    return check


def _action_checks(log: Px4Log, events: list[Px4Event]) -> list[Check]:
    out = []
    for e in events:
        what = f"t={e.time:.3f}s {e.label} action {e.outcome}"
        mode = NAV_STATES.get(e.action)
        if mode is None:
            continue  # a warning changes no mode
        check = Check(what, [], [Change(e.time + e.delay_s, mode)])
        if log.nav_state is None:
            check.undecided = "the log has no vehicle_status.nav_state"
        else:
            nav = log.nav_state
            slack = interval(nav.t, e.time) + 1.0
            window = (nav.t >= e.time - slack) & (nav.t <= e.time + e.delay_s + slack)
            check.logged = [Change(float(tk), int(v)) for tk, v in zip(nav.t[window], nav.values[window], strict=True)]
            if mode not in nav.values[window].tolist():
                check.problems.append(f"vehicle_status.nav_state never {mode} within {e.delay_s + slack:.1f}s")
        out.append(check)
    return out
