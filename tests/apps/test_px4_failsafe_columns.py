"""PX4's replay over columns (battery_warnings, commander_warning, the events of px4_replay) gives exactly what the
per-update loops it replaced gave: those loops are kept here as the oracles, run on a fixed draw of sequences with
connections dropping, armings, levels rising and falling, and on every real ULog's replay."""

from __future__ import annotations

import random
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from codegen.apps.failsafe.px4_actions import TEXTS, Action, Px4Settings, acting_parameter, battery_action
from codegen.apps.failsafe.px4_levels import (
    INITIALIZE_S,
    Px4Level,
    Thresholds,
    battery_warnings,
    commander_warning,
    determine_warning,
)
from codegen.apps.failsafe.px4_replay import Px4Event, _events, _worst

SHARED = Path(__file__).resolve().parents[2].parent / "shared"


def _battery_warnings_loop(boot_s: Any, remaining: Any, connected: Any, thresholds: Thresholds, latched: bool) -> Any:
    levels = determine_warning(remaining, thresholds)
    out = np.zeros(len(levels), np.int8)
    warning = int(Px4Level.NONE)
    unconnected_since = 0.0
    for k, (t, ok, level) in enumerate(zip(boot_s.tolist(), connected.tolist(), levels.tolist(), strict=True)):
        if not ok:
            unconnected_since = t
        if ok and t > unconnected_since + INITIALIZE_S:
            warning = max(warning, level) if latched else level
        out[k] = warning
    return out


def _commander_loop(per_battery: Any, t: Any, armed: Any) -> Any:
    worst = np.zeros(len(t), np.int8)
    for times, warnings, connected in per_battery:
        idx = np.searchsorted(times, t, side="right") - 1
        seen = idx >= 0
        latest = np.where(seen & connected[np.maximum(idx, 0)], warnings[np.maximum(idx, 0)], 0)
        worst = np.maximum(worst, latest.astype(np.int8))
    out = np.zeros(len(worst), np.int8)
    flag = 0
    for k, (w, a) in enumerate(zip(worst.tolist(), armed.tolist(), strict=True)):
        flag = max(flag, w) if a else w
        out[k] = flag
    return out


def _events_loop(log: Any, t: Any, armed: Any, flag: Any, per_battery: Any, thresholds: Thresholds,
                 settings: Px4Settings, release: Any) -> list[Px4Event]:  # fmt: skip
    out: list[Px4Event] = []
    previous, was_armed, at_arming = 0, False, Px4Level.NONE
    for tk, ak, fk in zip(t.tolist(), armed.tolist(), flag.tolist(), strict=True):
        level = Px4Level(fk)
        if ak and not was_armed:
            at_arming = level
        if ak and level > Px4Level.NONE and (level > previous or not was_armed):
            code = acting_parameter(settings.low_bat_act, level, at_arming, release)
            action = battery_action(code, level)
            battery, value, row = _worst(log, per_battery, tk, level)
            delay = settings.delay_s if action in (Action.RTL, Action.LAND) else 0.0
            out.append(Px4Event(tk, battery, level, value, thresholds.threshold(level), code, action, delay,
                                TEXTS[level], f"battery_status record {row} of battery {battery}"))  # fmt: skip
        previous, was_armed = fk, ak
    return out


def _draws(count: int) -> list[tuple[Any, ...]]:
    """Fixed sequences: a state of charge wandering down and up, connections dropping, armings coming and going."""
    rng = random.Random(30)
    out = []
    for _ in range(count):
        n = rng.randint(0, 80)
        boot = np.cumsum([rng.choice([0.1, 0.5, 1.0, 2.0, 2.5]) for _ in range(n)]) + rng.choice([0.0, 1.9, 10.0])
        soc = np.clip(np.cumsum([rng.uniform(-0.06, 0.04) for _ in range(n)]) + rng.uniform(0.0, 0.3), -0.1, 1.0)
        soc[[k for k in range(n) if rng.random() < 0.05]] = np.nan
        connected = np.array([rng.random() > 0.1 for _ in range(n)], bool)
        armed = np.array([rng.random() > 0.3 for _ in range(n)], bool)
        if rng.random() < 0.5:  # long armed runs too
            armed = np.repeat(np.array([rng.random() > 0.3 for _ in range(n // 8 + 1)], bool), 8)[:n]
        out.append((np.asarray(boot, np.float64), soc, connected, armed))
    return out


@pytest.mark.parametrize("latched", [False, True])
def test_battery_and_commander_warnings_are_the_loops(latched: bool) -> None:
    thresholds = Thresholds(0.15, 0.07, 0.05)
    for boot, soc, connected, armed in _draws(400):
        warnings = battery_warnings(boot, soc, connected, thresholds, latched=latched)
        assert warnings.dtype == np.int8
        assert warnings.tolist() == _battery_warnings_loop(boot, soc, connected, thresholds, latched).tolist()
        per_battery = [(boot, warnings, connected), (boot[::2], warnings[::2] // 2, connected[::2])]
        for t in (boot, boot + 0.25):
            flag = commander_warning(per_battery, t, armed)
            assert flag.dtype == np.int8 and flag.tolist() == _commander_loop(per_battery, t, armed).tolist()


@pytest.mark.parametrize("act", [0, 1, 2, 3])
def test_events_are_the_loops(act: int) -> None:
    thresholds = Thresholds(0.15, 0.07, 0.05)
    settings = Px4Settings(low_bat_act=act)
    fired = 0
    for boot, soc, connected, armed in _draws(300):
        warnings = battery_warnings(boot, soc, connected, thresholds)
        battery = SimpleNamespace(battery=1, remaining=soc)
        log = SimpleNamespace(batteries=[battery])
        per_battery = [(boot, warnings, connected)]
        flag = commander_warning(per_battery, boot, armed)
        for release in (None, (1, 13, 0), (1, 15, 2)):
            got = _events(log, boot, armed, flag, per_battery, thresholds, settings, release)  # type: ignore[arg-type]
            want = _events_loop(log, boot, armed, flag, per_battery, thresholds, settings, release)
            assert [repr(e) for e in got] == [repr(e) for e in want]
            fired += len(got)
    assert fired > 100  # the draws do fire


def test_every_real_ulog_replays_as_the_loops_did() -> None:
    from codegen.apps.failsafe import px4_replay
    from codegen.apps.failsafe.px4_log import NoBatteryRecords, read_px4_log

    logs = sorted((SHARED / "corpus").rglob("*.ulg"))
    if not logs:
        pytest.skip(f"no ULogs under {SHARED / 'corpus'}")
    replayed = 0
    for path in logs:
        try:
            log = read_px4_log(path)
        except (NoBatteryRecords, ValueError, OSError):
            continue
        calls: list[tuple[Any, ...]] = []
        real = px4_replay._events

        def spy(*args: Any, _real: Any = real, _calls: list[tuple[Any, ...]] = calls) -> list[Px4Event]:
            _calls.append(args)
            return list(_real(*args))

        px4_replay._events = spy  # type: ignore[assignment]
        try:
            px4_replay.replay_px4(log)
        finally:
            px4_replay._events = real
        for args in calls:
            assert [repr(e) for e in real(*args)] == [repr(e) for e in _events_loop(*args)], path.name
            replayed += 1
    assert replayed > 3
