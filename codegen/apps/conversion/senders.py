"""Named senders whose firmware is known to state a value wrong, read as they meant it (``battgen convert --sender``).

A policy (:mod:`codegen.ir.mapping_routes`) says how a *receiving* firmware converts what it gets; a sender is the
other end: a device that puts a wrong number on the bus in a known way. Its correction is applied to each record's
decoded messages before the converter runs, and every value it changes is named in the loss report (kind
``corrected``), so a converted record never hides that it was not taken as sent.

``nxp-bms772``: NXP's RDDRONE-BMS772 (and MR-BMS771) firmware fills UDRAL's ``Status.temperature_min_max`` with
the measured degrees Celsius plus its ``CELSIUS_TO_KELVIN``, which it defines as 272.15 (NXP rddrone-bms772
repository, ``src/uavcan.c``), not 273.15: every temperature it sends is 1 K below the true one. Read with its own
constant, a sent ``kelvin`` is ``kelvin - 272.15`` degrees Celsius, ``kelvin - 272.15 + 273.15`` kelvin.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from ...errors import BattgenError, did_you_mean

KELVIN_AT_0_C = 273.15  # UDRAL's kelvin, as uavcan.si.unit.temperature states it
NXP_CELSIUS_TO_KELVIN = 272.15  # NXP rddrone-bms772, src/uavcan.c: its CELSIUS_TO_KELVIN (one kelvin short)
STATUS = "cyphal.reg.udral.service.battery.Status_0_2"

Correct = Callable[[list[Any], Sequence[str], Any], list[Any]]


@dataclass(frozen=True)
class Sender:
    """A device whose records are corrected before conversion: ``endpoint`` is the converter side they are read
    as; ``correct(objects, aliases, report)`` returns the objects corrected (the input's are left as read)."""

    name: str
    endpoint: str
    doc: str
    correct: Correct


def _nxp_temperatures(objects: list[Any], aliases: Sequence[str], report: Any) -> list[Any]:
    """Each Status temperature read with NXP's 272.15: the kelvin it means is 1 K above the one sent."""
    if "status" not in aliases:
        return objects
    at = list(aliases).index("status")
    status = objects[at]
    if status is None:
        return objects
    fixed = copy.deepcopy(status)
    readings = fixed.get("temperature_min_max") if isinstance(fixed, dict) else fixed.temperature_min_max
    for i, reading in enumerate(readings or ()):
        sent = reading.get("kelvin") if isinstance(reading, dict) else reading.kelvin
        if not isinstance(sent, int | float) or not math.isfinite(sent):
            continue  # NaN: unknown, whatever constant the sender used
        meant = sent - NXP_CELSIUS_TO_KELVIN + KELVIN_AT_0_C
        if isinstance(reading, dict):
            reading["kelvin"] = meant
        else:
            reading.kelvin = meant
        report.add(
            "corrected",
            f"{STATUS}.temperature_min_max.{i}.kelvin",
            f"{sent!r} K read as {meant!r} K: nxp-bms772 adds 272.15, not 273.15, to its degrees Celsius",
        )
    return [fixed if k == at else o for k, o in enumerate(objects)]


SENDERS = {
    "nxp-bms772": Sender(
        "nxp-bms772",
        "udral",
        "NXP RDDRONE-BMS772 / MR-BMS771: temperatures sent as degrees Celsius + 272.15 (1 K low), read with 272.15",
        _nxp_temperatures,
    ),
}


def find_sender(name: str, endpoint: str) -> Sender:
    """The sender ``name`` for a conversion from ``endpoint``; a BattgenError naming the choices otherwise."""
    sender = SENDERS.get(name)
    if sender is None:
        raise BattgenError(
            f"--sender {name!r}: expected a known sender; " + did_you_mean(name, SENDERS, what="senders")
        )
    if sender.endpoint != endpoint:
        raise BattgenError(f"--sender {name}: its records are {sender.endpoint}'s, but this converts from {endpoint}")
    return sender
