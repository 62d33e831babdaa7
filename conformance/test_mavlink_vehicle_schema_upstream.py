"""The shipped schemas/mavlink/vehicle.xml (HEARTBEAT, SYS_STATUS, PARAM_VALUE, STATUSTEXT and their enums;
descriptions our own) against upstream's facts: the corpus's minimal.xml/common.xml
(``../shared/corpus/upstream/mavlink``) and the installed pymavlink's own generated common dialect: message ids,
CRC_EXTRA, wire lengths, fields (name, type, order, extensions, units, invalid markers, enums) and every enum
entry's value."""

from __future__ import annotations

import contextlib
import io
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
from pymavlink.dialects.v20 import common as pm
from pymavlink.generator import mavparse
from shared_data import UPSTREAM as UPSTREAM_CORPUS

from codegen.frontends import mavlink as frontend

ROOT = Path(__file__).resolve().parent.parent
VEHICLE_XML = ROOT / "schemas" / "mavlink" / "vehicle.xml"
UPSTREAM = UPSTREAM_CORPUS / "mavlink"
MESSAGES = {"HEARTBEAT": (0, 50), "SYS_STATUS": (1, 124), "PARAM_VALUE": (22, 220), "STATUSTEXT": (253, 83)}
ENUMS = ("MAV_TYPE", "MAV_AUTOPILOT", "MAV_MODE_FLAG", "MAV_STATE", "MAV_SYS_STATUS_SENSOR",
         "MAV_SYS_STATUS_SENSOR_EXTENDED", "MAV_PARAM_TYPE", "MAV_SEVERITY")  # fmt: skip


def _parse(path: Path) -> Any:
    with contextlib.redirect_stdout(io.StringIO()):
        return mavparse.MAVXML(str(path), mavparse.PROTOCOL_2_0)


def _upstream() -> tuple[dict[str, Any], dict[str, Any]]:
    if not UPSTREAM.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"{UPSTREAM} is missing")
        pytest.skip("../shared/corpus is not present")
    xs = [_parse(UPSTREAM / n) for n in ("minimal.xml", "common.xml")]
    return {m.name: m for x in xs for m in x.message}, {e.name: e for x in xs for e in x.enum}


def _field_facts(m: Any) -> list[tuple[Any, ...]]:
    return [(f.name, f.type, f.array_length, f.units, f.enum, f.invalid) for f in m.fields]


def test_messages_equal_the_corpus_and_pymavlink() -> None:
    messages, _ = _upstream()
    ours = {m.name: m for m in _parse(VEHICLE_XML).message}
    assert sorted(ours) == sorted(MESSAGES)
    schema = frontend.parse_file(VEHICLE_XML)
    for name, (msgid, crc_extra) in MESSAGES.items():
        mine, theirs = ours[name], messages[name]
        assert (mine.id, mine.crc_extra, mine.wire_length) == (theirs.id, theirs.crc_extra, theirs.wire_length)
        assert (mine.id, mine.crc_extra) == (msgid, crc_extra)
        assert _field_facts(mine) == _field_facts(theirs) and mine.extensions_start == theirs.extensions_start
        info = schema.message(f"mavlink.{name}").mavlink
        assert info is not None and (info.msg_id, info.crc_extra, info.max_length) == (
            msgid,
            crc_extra,
            mine.wire_length,
        )
        cls = pm.mavlink_map[msgid]
        assert (cls.msgname, cls.crc_extra) == (name, crc_extra)
        assert [f.name for f in mine.fields] == cls.fieldnames


def test_enums_equal_the_corpus_and_pymavlink() -> None:
    _, enums = _upstream()
    ours = {e.name: e for e in _parse(VEHICLE_XML).enum}
    assert sorted(ours) == sorted(ENUMS)
    for name in ENUMS:
        mine = {e.name: e.value for e in ours[name].entry if not e.name.endswith("_ENUM_END")}
        theirs = {e.name: e.value for e in enums[name].entry if not e.name.endswith("_ENUM_END")}
        assert mine == theirs, name
        assert ours[name].bitmask == enums[name].bitmask, name
        # the installed pymavlink's bundled common dialect is older: each constant it has agrees
        shared = {k: v for k, v in vars(pm).items() if k in mine}
        assert all(mine[k] == v for k, v in shared.items()), name
        assert shared or name == "MAV_SYS_STATUS_SENSOR_EXTENDED", name  # newer than the bundled dialect


def test_descriptions_are_ours() -> None:
    """Facts are upstream's; no description is upstream's text (whitespace aside)."""
    _upstream()
    theirs: set[str] = set()
    for name in ("minimal.xml", "common.xml"):
        theirs |= {" ".join((e.text or "").split()) for e in ET.parse(UPSTREAM / name).getroot().iter()}
    theirs.discard("")
    ours = [
        " ".join((e.text or "").split())
        for e in ET.parse(VEHICLE_XML).getroot().iter()
        if e.tag in ("description", "field")
    ]
    assert ours and not [d for d in ours if d in theirs and len(d) > 12]
