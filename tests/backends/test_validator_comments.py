"""The comment above each field's check in validate() (validators/describe.py) says what the check does:
each claim read here is tried on the generated class, so a comment cannot drift from the test below it."""

from __future__ import annotations

import inspect
import math

from generated.dronecan.uavcan.equipment.power import BatteryInfo
from generated.uorb import BatteryStatus


def _comment(cls: type, field: str) -> str:
    """The comment above the field's check, its wrapped lines joined."""
    lines = [line.strip() for line in inspect.getsource(cls.validate).splitlines()]  # type: ignore[attr-defined]
    start = next(i for i, line in enumerate(lines) if line.startswith(f"# {field} ("))
    end = next(i for i in range(start + 1, len(lines)) if not lines[i].startswith("#"))
    return " ".join([lines[start], *(line[2:] for line in lines[start + 1 : end])])


def _flagged(obj: object, field: str) -> bool:
    """Whether the field's own check (not a cross-field rule) reports it."""
    return any(v.path == field and not v.rule.startswith("cross-field:") for v in obj.validate())  # type: ignore[attr-defined]


def test_sentinel_and_type_claims_hold() -> None:
    text = _comment(BatteryInfo, "state_of_health_pct")
    assert text == (
        "# state_of_health_pct (1092.BatteryInfo.uavcan:37): fits uint7; "
        "STATE_OF_HEALTH_UNKNOWN means unknown (accepted)"
    )
    assert not _flagged(BatteryInfo(state_of_health_pct=127), "state_of_health_pct")  # the sentinel: accepted
    assert _flagged(BatteryInfo(state_of_health_pct=128), "state_of_health_pct")  # beyond uint7


def test_bitmask_claim_holds() -> None:
    assert _comment(BatteryInfo, "status_flags").endswith("fits uint11; bits of STATUS_FLAG only")
    assert not _flagged(BatteryInfo(status_flags=1 | 256), "status_flags")
    assert _flagged(BatteryInfo(status_flags=1 << 11), "status_flags")


def test_bounds_claim_holds() -> None:
    text = _comment(BatteryStatus, "remaining")
    assert text.endswith("fits float32; 0 <= value <= 1; -1 means unknown (accepted)")
    assert not _flagged(BatteryStatus(remaining=-1.0), "remaining")
    assert _flagged(BatteryStatus(remaining=1.5), "remaining")
    assert not _flagged(BatteryInfo(temperature=math.nan), "temperature")
    assert _comment(BatteryInfo, "temperature").endswith("fits float16; NaN means unknown (accepted)")
