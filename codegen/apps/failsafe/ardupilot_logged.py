"""What an ArduPilot DataFlash log recorded of its battery failsafe, and the ArduPilot replay checked against it.

The firmware records each battery failsafe it acts on three ways (ArduPilot master):

- ``ERR`` with ``Subsys`` 6 (``LogErrorSubsystem::FAILSAFE_BATT``) and ``ECode`` 1 (``FAILSAFE_OCCURRED``):
  ``ArduCopter/events.cpp`` ``Copter::handle_battery_failsafe`` writes it for every level it handles (the vehicles'
  handlers do the same), before ArduPilot 3.6 ``failsafe_battery_event`` did;
- ``MSG`` ``Battery 1 is low 10.40V used 2500 mAh`` (``AP_BattMonitor::check_failsafes``; before 3.6 ``Low battery``);
- ``MODE`` with ``Rsn`` 4 (``ModeReason::BATTERY_FAILSAFE``) when the action changes the mode (logs before ModeReason
  was logged have no ``Rsn``).

The replay's events are compared with the ``ERR`` records (one per event, each within one battery sample) and its
mode-changing outcomes with the ``MODE`` records of that reason. The arming state is the battery view's, as for the
replay. A firmware that still used the older names (``FS_BATT_VOLTAGE``: before 3.6) checked its battery while
disarmed as well and only acted while armed (the corpus's ArduCopter 3.4 tlog says "Low battery" disarmed), so a
logged failsafe while disarmed is noted, not compared.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...inputs.dataflash.log import open_log
from ..battery.columns import NDArray
from .evaluator import Event
from .logs import SampleTable
from .replay_checks import Change, Check, within_one_sample

FAILSAFE_BATT = 6  # LogErrorSubsystem::FAILSAFE_BATT
FAILSAFE_OCCURRED = 1  # LogErrorCode::FAILSAFE_OCCURRED
BATTERY_FAILSAFE_REASON = 4  # ModeReason::BATTERY_FAILSAFE
TEXT = re.compile(r"Battery (\d+) is (low|critical)\b|Low [Bb]attery")
MODE_OUTCOMES = frozenset({"rtl", "land", "smart_rtl", "hold", "surface", "qland", "loiter_qland", "auto_land"})


@dataclass(frozen=True)
class Logged:
    """One record of the battery failsafe: its time (s since the log's start), kind and what it says."""

    t: float
    record: str  # "ERR", "MSG" or "MODE"
    detail: str


@dataclass
class LoggedFailsafe:
    records: list[Logged]
    mode_reasons: bool  # the log's MODE records carry Rsn


def logged_failsafes(path: Path, name: str, origin_us: int) -> LoggedFailsafe:
    """The battery failsafe records of a DataFlash log (one filtered pass over ERR, MSG and MODE)."""
    out = LoggedFailsafe([], False)
    for msg in open_log(path, name).messages({"ERR", "MSG", "MODE"}):
        when = msg.when_s
        if when is None:
            continue
        t = when - origin_us / 1e6
        fields = msg.fields
        if msg.type == "ERR" and fields.get("Subsys") == FAILSAFE_BATT:
            out.records.append(Logged(t, "ERR", f"subsystem 6 code {fields.get('ECode')}"))
        elif msg.type == "MSG":
            text = fields.get("Message")
            text = text.decode("ascii", "replace") if isinstance(text, bytes) else text
            if isinstance(text, str) and TEXT.search(text):
                out.records.append(Logged(t, "MSG", text.rstrip("\x00")))
        elif msg.type == "MODE":
            if "Rsn" in fields:
                out.mode_reasons = True
                if fields["Rsn"] == BATTERY_FAILSAFE_REASON:
                    out.records.append(Logged(t, "MODE", f"mode {fields.get('Mode')} for the battery failsafe"))
    return out


def ardupilot_checks(logged: LoggedFailsafe, events: list[Event], sample_t: NDArray, armed_t: NDArray) -> list[Check]:
    """The replay's events against the log's records (``sample_t``: the battery samples' times; ``armed_t``: whether
    the vehicle was armed at each of them)."""
    errors = [r for r in logged.records if r.record == "ERR" and r.detail.endswith(f"code {FAILSAFE_OCCURRED}")]
    disarmed = [r for r in errors if not _armed_at(sample_t, armed_t, r.t)]
    check = Check(
        "ERR subsystem 6 (FAILSAFE_BATT)",
        [Change(r.t, 1) for r in errors],
        [Change(e.time, 1) for e in events],
    )
    if disarmed:
        check.undecided = (
            f"{len(disarmed)} logged while disarmed (first at {disarmed[0].t:.3f}s): firmware before 3.6 checked its "
            "battery disarmed too; today's AP_BattMonitor, which the replay follows, only while armed"
        )
    else:
        check.problems = within_one_sample(check.logged, check.replayed, [sample_t])
    modes = Check(
        "MODE for the battery failsafe (Rsn 4)",
        [Change(r.t, 1) for r in logged.records if r.record == "MODE"],
        [Change(e.time, 1) for e in events if e.executed and e.outcome in MODE_OUTCOMES],
    )
    if not logged.mode_reasons:
        modes.undecided = "the log's MODE records carry no reason (Rsn)"
    else:
        modes.problems = within_one_sample(modes.logged, modes.replayed, [sample_t])
    return [check, modes]


def check_log(path: Path, name: str, table: SampleTable, events: list[Event]) -> list[Check]:
    """A log's own failsafe records against the ArduPilot replay of its samples (``table``): a DataFlash log's ERR and
    MODE records; a tlog's STATUSTEXT is not read, which its check says; other inputs record nothing to compare."""
    context = table.context
    if context is None or context.kind not in ("dataflash", "tlog"):
        return []
    if context.kind == "tlog":
        replayed = [Change(e.time, 1) for e in events]
        why = "a tlog records the failsafe as STATUSTEXT, which battgen does not read (no bundled STATUSTEXT schema)"
        return [Check("STATUSTEXT of the battery failsafe", [], replayed, undecided=why)]
    t, _, _, _, _, armed, _ = table.sorted_columns()
    return ardupilot_checks(logged_failsafes(path, name, context.start_us or 0), events, t, armed == 1.0)


def _armed_at(t: NDArray, armed: NDArray, when: float) -> bool:
    k = int(np.searchsorted(t, when, side="right")) - 1
    return bool(k >= 0 and armed[k])
