"""Whose battery failsafe ``battgen failsafe`` replays a stream through: PX4's or ArduPilot's.

Given (``--firmware``) it is that; else the given parameters name it (ArduPilot's ``BATT*_`` groups, PX4's ``BAT_*``
thresholds and ``COM_*`` battery actions); else the log says (:mod:`codegen.inputs.files.kinds`: a ULog is PX4's own
format; a DataFlash log, a tlog and JSON Lines samples go through ArduPilot's, whose replay reads them).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from .stream import batt_parameter_count

FIRMWARES = ("px4", "ardupilot")
PX4_PREFIXES = ("BAT_", "BAT1_", "COM_LOW_BAT", "COM_FAIL_ACT", "COM_FLTT_LOW", "COM_ARM_BAT")


def px4_parameter_count(values: Mapping[str, float]) -> int:
    """How many of ``values`` are PX4's battery failsafe parameters (``BAT_*`` thresholds, ``COM_*`` actions)."""
    return sum(1 for name in values if name.startswith(PX4_PREFIXES))


def choose_firmware(
    given: str | None, parameters: Mapping[str, float] | None, where: str, stream: Path
) -> tuple[str, str]:
    """The firmware and the words saying why (``where``: the parameters' file, for those words)."""
    if given:
        if given not in FIRMWARES:
            raise ValueError(f"expected a firmware among {', '.join(FIRMWARES)}, got {given!r}")
        return given, "given"
    if parameters:
        if batt_parameter_count(parameters):
            return "ardupilot", f"{where} holds ArduPilot's BATT*_ parameters"
        if px4_parameter_count(parameters):
            return "px4", f"{where} holds PX4's BAT_/COM_ parameters"
    from ...inputs.files.kinds import detect  # the IR's formats come along: only a stream without parameters asks

    if detect(stream) == "ulog":
        return "px4", "the log is a PX4 ULog"
    return "ardupilot", "the log's"
