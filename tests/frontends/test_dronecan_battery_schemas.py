"""The DroneCAN battery definitions ArduPilot and CUAV use, shipped in schemas/dronecan, are the project's own
text: the same definitions as upstream's (names, types, order, constants, so the same signature), with
comments of our own. conformance/test_dsdl_pydronecan.py compares every bundled type with pydronecan's reading
of today's upstream DSDL; here, that no line of upstream's comments was carried over."""

from __future__ import annotations

import pytest
from conftest import ROOT
from shared_data import SHARED, require

UPSTREAM = SHARED / "corpus" / "realworld3b" / "dsdl" / "DSDL"  # dronecan/DSDL as of February 2026
OURS = ROOT / "schemas" / "dronecan"

WRITTEN = [
    "uavcan/equipment/power/1092.BatteryInfo.uavcan",
    "ardupilot/equipment/power/20004.BatteryInfoAux.uavcan",
    "ardupilot/equipment/power/20010.BatteryContinuous.uavcan",
    "ardupilot/equipment/power/20011.BatteryPeriodic.uavcan",
    "ardupilot/equipment/power/20012.BatteryCells.uavcan",
    "ardupilot/equipment/power/20500.BatteryTag.uavcan",
    "cuav/equipment/power/20300.CBAT.uavcan",
]


def _comments(text: str) -> set[str]:
    """The prose of a file's comments (a comment's text after its unit tag), longer than a few words."""
    found = set()
    for line in text.splitlines():
        _, _, comment = line.partition("#")
        prose = comment.split("]", 1)[-1].strip(" :") if comment.lstrip().startswith("[") else comment.strip()
        if len(prose.split()) > 3:
            found.add(prose)
    return found


def _definition(text: str) -> list[str]:
    """The lines that define the type (comments and blank lines dropped, spacing normalised)."""
    return [" ".join(line.split("#", 1)[0].split()) for line in text.splitlines() if line.split("#", 1)[0].strip()]


@pytest.mark.parametrize("path", WRITTEN)
def test_our_text_defines_upstreams_type_in_our_words(path: str) -> None:
    upstream = require(UPSTREAM / path).read_text(encoding="utf-8")
    ours = (OURS / path).read_text(encoding="utf-8")
    assert _definition(ours) == _definition(upstream)
    assert _comments(ours) and not _comments(ours) & _comments(upstream), path
