"""The DroneCAN battery definitions ArduPilot and PX4 use today, shipped in schemas/dronecan, equal
upstream's: each file is the ``dronecan`` package's DSDL copy (DroneCAN/DSDL, MIT licence) byte for
byte, followed by a comment naming its source."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import ROOT

dronecan = pytest.importorskip("dronecan")
SPECS = Path(dronecan.__file__).parent / "dsdl_specs"
OURS = ROOT / "schemas" / "dronecan"

COPIED = [
    "ardupilot/equipment/power/20010.BatteryContinuous.uavcan",
    "ardupilot/equipment/power/20011.BatteryPeriodic.uavcan",
    "ardupilot/equipment/power/20012.BatteryCells.uavcan",
    "ardupilot/equipment/power/20500.BatteryTag.uavcan",
    "cuav/equipment/power/20300.CBAT.uavcan",
]


@pytest.mark.parametrize("path", COPIED)
def test_shipped_definition_is_upstreams_with_a_source_note(path: str) -> None:
    upstream = (SPECS / path).read_bytes()
    ours = (OURS / path).read_bytes()
    assert ours.startswith(upstream), f"{path} differs from {SPECS / path}"
    note = ours[len(upstream) :].decode("utf-8")
    lines = [line for line in note.splitlines() if line]
    assert lines and all(line.startswith("#") for line in lines)  # comments only: no field, no constant
    assert f"Source: DroneCAN DSDL (github.com/DroneCAN/DSDL, MIT licence), {path}" in note
    assert "as bundled in\n# pydronecan" in note  # which copy was taken (the version is in the note)
