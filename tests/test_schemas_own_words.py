"""The bundled schemas are written in our words: facts are upstream's (checked against upstream's files by
tests/test_uorb_schemas_upstream.py, conformance/test_mavlink_*_schema_upstream.py, conformance/test_dsdl_pydronecan.py,
conformance/test_cyphal_pydsdl.py, conformance/test_dtschema_bindings.py), descriptions and comments are not.

Two checks against the upstream file each schema takes its facts from (../shared/corpus/): no description or
comment of 30 characters or more is upstream's word for word (as a whole, a sentence, or one line of the
upstream file), and no element (field, constant, enum entry, message, property) has upstream's description
for the same element.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import pytest
from schema_facts import prose, shared_lines
from shared_data import SHARED, UPSTREAM, missing

from codegen.frontends import devicetree, uorb
from codegen.ir import Message

ROOT = Path(__file__).resolve().parent.parent
SCHEMAS = ROOT / "schemas"
CORPUS = SHARED / "corpus"
PX4 = UPSTREAM / "px4_msgs" / "main"
V0 = CORPUS / "realworld2" / "px4" / "BatteryStatusV0.upstream.msg"
MAVLINK = UPSTREAM / "mavlink"
KERNEL = CORPUS / "realworld2" / "linux"
DSDL = CORPUS / "realworld3b" / "dsdl" / "DSDL"
CYPHAL = CORPUS / "cyphal"
SHORTEST_ELEMENT = 12  # shorter descriptions ("Too hot.", "Rocket.") are names more than prose


def _pairs() -> Iterator[tuple[str, list[Path]]]:
    yield "uorb/BatteryStatus.msg", [PX4 / "BatteryStatus.msg"]
    yield "uorb/BatteryInfo.msg", [PX4 / "BatteryInfo.msg"]
    yield "uorb/BatteryStatusV0.msg", [V0]
    yield "mavlink/battery.xml", [MAVLINK / "common.xml", MAVLINK / "development.xml"]
    yield "mavlink/vehicle.xml", [MAVLINK / "minimal.xml", MAVLINK / "common.xml"]
    yield "devicetree/power/supply/battery.yaml", sorted(KERNEL.glob("battery.*.yaml"))
    for path in sorted((SCHEMAS / "dronecan").rglob("*.uavcan")):
        yield path.relative_to(SCHEMAS).as_posix(), [DSDL / path.relative_to(SCHEMAS / "dronecan")]
    for path in sorted((SCHEMAS / "cyphal").rglob("*.dsdl")):
        yield path.relative_to(SCHEMAS).as_posix(), [CYPHAL / path.relative_to(SCHEMAS / "cyphal")]


PAIRS = dict(_pairs())


def _upstream(paths: list[Path]) -> list[Path]:
    if not paths or not all(p.is_file() for p in paths):
        missing(", ".join(p.as_posix() for p in paths) or "the upstream files")
    return paths


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_no_long_comment_is_upstreams(name: str) -> None:
    ours = SCHEMAS / name
    assert prose(ours), f"{name} has no descriptions to check"
    assert shared_lines(ours, _upstream(PAIRS[name])) == []


def test_the_check_finds_upstreams_text(tmp_path: Path) -> None:
    """The check is not vacuous: upstream's own file, under our name, fails it."""
    upstream = _upstream([PX4 / "BatteryStatus.msg"])[0]
    copy = tmp_path / "BatteryStatus.msg"
    copy.write_text(upstream.read_text(encoding="utf-8") + "# " + "a comment of our own, long enough\n")
    found = shared_lines(copy, [upstream])
    assert "Battery current average (for FW average in level flight)" in found
    assert "a comment of our own, long enough" not in found


def _docs(message: Message) -> dict[str, str]:
    """Every described element of a message by a name that is the same in ours and upstream's."""
    out = {"": message.doc}
    out.update({f"field {f.name}": f.doc for f in message.fields})
    out.update({f"constant {c.name}": c.doc for c in message.constants})
    out.update({f"{e.short_name}.{x.name}": x.doc for e in message.enums for x in e.entries})
    return out


def _same_words(ours: dict[str, str], theirs: dict[str, str]) -> list[str]:
    def fold(text: str) -> str:
        return " ".join(text.split()).rstrip(".").lower()

    def restates_name(key: str, text: str) -> bool:  # "Ground rover." for MAV_TYPE_GROUND_ROVER: the name
        return key.lower().replace("_", " ").endswith(fold(text))

    return [
        f"{key}: {text!r}"
        for key, text in ours.items()
        if len(fold(text)) >= SHORTEST_ELEMENT
        and fold(text) == fold(theirs.get(key, ""))
        and not restates_name(key, text)
    ]


@pytest.mark.parametrize(("ours", "theirs"), [
    ("BatteryStatus.msg", PX4 / "BatteryStatus.msg"),
    ("BatteryInfo.msg", PX4 / "BatteryInfo.msg"),
    ("BatteryStatusV0.msg", V0),
])  # fmt: skip
def test_no_uorb_element_has_upstreams_description(ours: str, theirs: Path, tmp_path: Path) -> None:
    copy = tmp_path / ours  # parsed under our name, so that both are the same message
    copy.write_text(_upstream([theirs])[0].read_text(encoding="utf-8"), encoding="utf-8")
    name = f"uorb.{ours.removesuffix('.msg')}"
    mine = _docs(uorb.parse_file(SCHEMAS / "uorb" / ours).message(name))
    assert _same_words(mine, _docs(uorb.parse_file(copy).message(name))) == []


def _xml_docs(paths: list[Path]) -> dict[str, str]:
    out: dict[str, str] = {}
    for path in paths:
        for element in ET.parse(path).getroot().iter():
            name = element.attrib.get("name")
            description = element.find("description")
            if element.tag in ("enum", "entry", "message") and name and description is not None:
                out[name] = description.text or ""
            if element.tag == "message" and name:
                out.update({f"{name}.{f.attrib['name']}": f.text or "" for f in element.iter("field")})
    return out


@pytest.mark.parametrize("name", ["battery.xml", "vehicle.xml"])
def test_no_mavlink_element_has_upstreams_description(name: str) -> None:
    theirs = _xml_docs(_upstream([MAVLINK / "minimal.xml", MAVLINK / "common.xml", MAVLINK / "development.xml"]))
    mine = _xml_docs([SCHEMAS / "mavlink" / name])
    assert mine and _same_words(mine, theirs) == []


def test_no_devicetree_property_has_upstreams_description(tmp_path: Path) -> None:
    mine = devicetree.parse_dir(SCHEMAS / "devicetree").message("devicetree.power.supply.battery")
    ours = {"": mine.doc, **{f.name: f.doc for f in mine.fields}}
    for upstream in _upstream(sorted(KERNEL.glob("battery.*.yaml"))):
        folder = tmp_path / upstream.stem / "power" / "supply"
        folder.mkdir(parents=True)
        (folder / "battery.yaml").write_text(upstream.read_text(encoding="utf-8"), encoding="utf-8")
        theirs = devicetree.parse_dir(folder.parents[1]).message("devicetree.power.supply.battery")
        assert _same_words(ours, {"": theirs.doc, **{f.name: f.doc for f in theirs.fields}}) == [], upstream.name
