"""Every real PX4 log of ../shared replayed through PX4's battery failsafe and checked against what its firmware
logged; what the replay compares with is read again with pyulog, the reference reader.

``LOGS`` lists each log with the transitions its firmware logged: battery_status.warning per battery and
failsafe_flags.battery_warning (None: the log does not record the topic), as (seconds since the log's start, level).
"""

from __future__ import annotations

import numpy as np
import pytest
from shared_data import require, shared

from codegen.apps.failsafe.px4_log import read_px4_log
from codegen.apps.failsafe.px4_replay import replay_px4
from codegen.apps.failsafe.replay_checks import changes

BATTERY_WARNINGS_61 = [
    (23.775, 1), (25.375, 2), (26.376, 1), (27.575, 0), (27.775, 1), (28.175, 0), (32.975, 1), (33.576, 0),
    (33.776, 1), (51.375, 2), (51.775, 3), (55.975, 1), (57.775, 2), (57.976, 1), (59.375, 2), (60.176, 3),
    (60.376, 2), (61.375, 1), (61.775, 2), (61.976, 1), (64.775, 2), (68.775, 1), (69.575, 2), (69.775, 1),
    (70.975, 2), (71.175, 1), (71.575, 2), (71.775, 1), (72.175, 2), (72.376, 1), (72.575, 2), (72.776, 1),
    (72.975, 2), (73.575, 1), (73.975, 2), (74.175, 1), (75.775, 0), (75.975, 1), (76.176, 0),
]  # fmt: skip
LOGS: dict[str, tuple[dict[int, list[tuple[float, int]]], list[tuple[float, int]] | None]] = {
    "data/ulog/sample_log_small.ulg": ({1: [], 2: []}, None),
    "data/ulog/sample_px4_events.ulg": ({1: []}, []),
    "corpus/realworld3/ulog/auterion_6ba1abc7-b433-4029-b8f5-3b2bb12d3b6c.ulg": ({1: []}, None),
    "corpus/realworld3/ulog/auterion_esc_status_log.ulg": ({1: []}, None),
    "corpus/realworld3/ulog/auterion_quadrotor_local.ulg": (
        {1: [(77.066, 1), (80.867, 0), (81.267, 1), (81.466, 0), (81.666, 1), (85.466, 0), (86.266, 1), (86.866, 0)]},
        [(77.019, 1), (91.555, 0)],
    ),
    "corpus/realworld3/ulog/fsyrh_log_123_2024-3-1-14-47-02.ulg": ({1: []}, []),
    "corpus/realworld3/ulog/fsyrh_log_61_2024-2-6-16-27-02.ulg": (
        {1: BATTERY_WARNINGS_61},
        [(23.823, 1), (25.356, 2), (52.066, 3), (78.009, 0)],
    ),
    "corpus/realworld3/ulog/px4tools_19_56_46.ulg": ({1: []}, None),
    "corpus/realworld3/ulog/px4ulogtests_14_19_29.ulg": ({1: [], 2: []}, None),
    "corpus/realworld3/ulog/pyulog_sample_logging_tagged_and_default_params.ulg": ({1: []}, None),
    "corpus/realworld3b/ulog/roboto_test.ulg": ({1: [(0.139, 3)]}, None),
}


def _rounded(found: list[tuple[float, int]]) -> list[tuple[float, int]]:
    return [(round(t, 3), v) for t, v in found]


@pytest.mark.parametrize("name", sorted(LOGS))
def test_replay_reproduces_the_logged_transitions(name: str) -> None:
    battery_changes, flag_changes = LOGS[name]
    log = read_px4_log(require(shared(name)))
    replay = replay_px4(log)
    checks = {c.what: c for c in replay.checks}
    for battery, expected in battery_changes.items():
        check = checks[f"battery {battery} battery_status.warning"]
        assert _rounded([(c.t, c.value) for c in check.logged]) == expected
        assert check.ok, check.problems
    flags = checks["failsafe_flags.battery_warning"]
    if flag_changes is None:
        assert flags.undecided and not flags.logged  # says so rather than passing
    else:
        assert _rounded([(c.t, c.value) for c in flags.logged]) == flag_changes
        assert flags.ok, flags.problems
    remaining = checks["failsafe_flags.battery_low_remaining_time"]
    if flag_changes is None:
        assert remaining.undecided
    else:  # v1.14+: no log's flight ran short of time, and the replay agrees wherever the log had an RTL estimate
        assert remaining.ok or "no rtl_time_estimate" in remaining.undecided, remaining.problems
    assert all(not c.problems for c in replay.checks)
    older = replay.release is not None and replay.release[:2] < (1, 14)
    assert bool(replay.notes) == older  # a release before the failsafe framework says what it takes on trust


@pytest.mark.parametrize("name", sorted(LOGS))
def test_what_the_replay_compares_with_is_what_pyulog_reads(name: str) -> None:
    from pyulog import ULog

    path = require(shared(name))
    ulog = ULog(str(path), ["battery_status", "failsafe_flags"])
    start = ulog.start_timestamp
    ours = read_px4_log(path)
    theirs = {d.multi_id + 1: d.data for d in ulog.data_list if d.name == "battery_status"}
    assert sorted(theirs) == [b.battery for b in ours.batteries]  # one battery per instance (id = multi_id + 1)
    for battery in ours.batteries:
        data = theirs[battery.battery]
        t = (data["timestamp"].astype(np.int64) - start) / 1e6
        assert np.allclose(battery.t, t, atol=1e-6)
        assert np.array_equal(battery.remaining.astype(np.float32), data["remaining"])
        assert battery.warning.tolist() == data["warning"].tolist()
        assert battery.connected.tolist() == data["connected"].astype(bool).tolist()
    flags = [d.data for d in ulog.data_list if d.name == "failsafe_flags"]
    if flags:
        t = (flags[0]["timestamp"].astype(np.int64) - start) / 1e6
        assert ours.failsafe_warning is not None
        assert changes(ours.failsafe_warning.t, ours.failsafe_warning.values) == changes(
            t, flags[0]["battery_warning"].astype(np.int64)
        )
    else:
        assert ours.failsafe_warning is None


def test_the_v114_flight_events_and_actions() -> None:
    # COM_LOW_BAT_ACT 0: each rise a warning, as the log's "[failsafe] Failsafe activated" messages at 23.8, 25.4 and
    # 51.7 s (pyulog's logged messages) and its nav_state, which stays Altitude (1)
    from pyulog import ULog

    path = require(shared("corpus/realworld3/ulog/fsyrh_log_61_2024-2-6-16-27-02.ulg"))
    replay = replay_px4(read_px4_log(path))
    assert [(round(e.time, 3), e.level.name, e.action.name) for e in replay.events] == [
        (23.775, "LOW", "WARN"),
        (25.375, "CRITICAL", "WARN"),
        (51.775, "EMERGENCY", "WARN"),
    ]
    ulog = ULog(str(path), ["vehicle_status"])
    notified = [
        (m.timestamp - ulog.start_timestamp) / 1e6 for m in ulog.logged_messages if "Failsafe activated" in m.message
    ]
    for event, when in zip(replay.events, notified, strict=True):
        assert abs(event.time - when) <= 0.6  # within one sample of battery_status (0.2 s) or failsafe_flags (0.55 s)
    status = next(d.data for d in ulog.data_list if d.name == "vehicle_status")
    assert set(status["nav_state"][status["timestamp"] > replay.events[0].time * 1e6 + ulog.start_timestamp]) == {1}
