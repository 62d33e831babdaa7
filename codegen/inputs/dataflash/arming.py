"""When a DataFlash log's vehicle was armed: one rule, from ArduPilot's logger.

``AP_Logger_Backend::ShouldLog`` refuses a non-critical write while the vehicle is disarmed unless
``AP_Logger::log_while_disarmed()`` holds (``LOG_DISARMED`` != 0, or a few seconds around an arming
attempt). So a log written with ``LOG_DISARMED=0`` -- and one from firmware before that parameter
(ArduCopter 3.x started the log file on arming, ``start_logging()`` in ``init_arm_motors``) -- holds
records only from arming on, and often no ARM record at all: it is armed from its first record.
A log written with ``LOG_DISARMED`` != 0 starts disarmed. Arming records are logged on a change,
so where a log has one, the state before it is the other (a log whose first is a DISARMED was
armed from its start, whatever ``LOG_DISARMED`` says). From that initial state ``ARM.ArmState``
and the ``EV`` events 10 (ARMED), 15 (AUTO_ARMED, which implies armed) and 11 (DISARMED) change it.
"""

from __future__ import annotations

from collections.abc import Mapping

EV_ARMED, EV_DISARMED, EV_AUTO_ARMED = 10, 11, 15  # AP_Logger LogEvent ids
EV_STATES = {EV_ARMED: True, EV_AUTO_ARMED: True, EV_DISARMED: False}


def armed_at_start(parameters: Mapping[str, float], first_change: bool | None) -> bool:
    """The arming state at the log's first record: the opposite of its first arming record's state
    (``first_change``) when it has one, else from ``LOG_DISARMED`` (absent: 0, logging from arming)."""
    if first_change is not None:
        return not first_change
    return parameters.get("LOG_DISARMED", 0.0) == 0.0


def event_state(event_id: float | None) -> bool | None:
    """The arming state an ``EV`` id states, or None for another event."""
    return None if event_id is None else EV_STATES.get(int(event_id))
