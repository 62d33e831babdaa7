"""The shipped schemas/mavlink/battery.xml against upstream's own definitions (the corpus of
mavlink/mavlink's message_definitions, see ../shared/corpus/upstream/mavlink/SOURCE.md).

- Every enum and message element of battery.xml has the facts of the element of the same name in
  common.xml or development.xml: attributes (ids, names, types, units, invalid markers, enum values,
  bitmask), children and their order; the descriptions are ours (tests/test_schemas_own_words.py).
- Its CRC_EXTRA values, by pymavlink's parser and by ours, are those of the upstream dialect.
- The generated codecs of BATTERY_INFO and BATTERY_STATUS_V2 give the same payloads and frames
  as a pymavlink module that mavgen generates from the corpus's development.xml (the installed
  pymavlink's bundled dialects have neither message yet).
"""

from __future__ import annotations

import contextlib
import importlib
import io
import math
import sys
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymavlink.generator import mavgen, mavparse
from shared_data import UPSTREAM

from codegen.frontends import mavlink as frontend
from codegen.ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, StringType
from generated import _mavlink as runtime
from generated.mavlink import BatteryInfo, BatteryStatus, BatteryStatusV2

ROOT = Path(__file__).resolve().parent.parent
CORPUS = UPSTREAM / "mavlink"
BATTERY_XML = ROOT / "schemas" / "mavlink" / "battery.xml"
UPSTREAM = ("common.xml", "development.xml")
FAST = settings(max_examples=40, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))


PROSE = ("description", "field")  # elements whose text is a description (ours), not a fact


def _shape(e: ET.Element) -> tuple[Any, ...]:
    """An element's facts as comparable data: tag, attributes, children (a description's text left out)."""
    text = "" if e.tag in PROSE else " ".join((e.text or "").split())
    return (e.tag, sorted(e.attrib.items()), text, [_shape(c) for c in e])


def _named(path: Path, tag: str) -> dict[str, ET.Element]:
    return {e.attrib["name"]: e for e in ET.parse(path).getroot().iter(tag)}


@pytest.mark.parametrize("tag", ["enum", "message"])
def test_every_element_has_upstreams_facts(tag: str) -> None:
    ours = _named(BATTERY_XML, tag)
    upstream: dict[str, ET.Element] = {}
    for name in UPSTREAM:
        upstream.update(_named(CORPUS / name, tag))
    assert ours, tag
    for name, element in ours.items():
        assert name in upstream, name
        assert _shape(element) == _shape(upstream[name]), name


def test_battery_xml_holds_upstreams_battery_messages_and_their_enums() -> None:
    assert sorted(_named(BATTERY_XML, "message")) == ["BATTERY_INFO", "BATTERY_STATUS", "BATTERY_STATUS_V2"]
    used = {f.attrib["enum"] for f in ET.parse(BATTERY_XML).getroot().iter("field") if "enum" in f.attrib}
    assert used == set(_named(BATTERY_XML, "enum"))  # every enum a field names, and no other


def _mavparse_messages(path: Path) -> dict[str, Any]:
    out: dict[str, Any] = {}
    queue, seen = [path.resolve()], set()
    with contextlib.redirect_stdout(io.StringIO()):
        while queue:
            p = queue.pop(0)
            if p not in seen:
                seen.add(p)
                x = mavparse.MAVXML(str(p), mavparse.PROTOCOL_2_0)
                out.update({m.name: m for m in x.message})
                queue.extend((p.parent / inc).resolve() for inc in x.include)
    return out


def test_crc_extra_equals_upstream_dialect() -> None:
    upstream = _mavparse_messages(CORPUS / "development.xml")
    shipped = _mavparse_messages(BATTERY_XML)
    ours = frontend.parse_file(BATTERY_XML)
    for name, theirs in shipped.items():
        info = ours.message(f"mavlink.{name}").mavlink
        assert info is not None
        want = (upstream[name].id, upstream[name].crc_extra, upstream[name].wire_length)
        assert (theirs.id, theirs.crc_extra, theirs.wire_length) == want, name
        assert (info.msg_id, info.crc_extra, info.max_length) == want, name
    assert {n: m.crc_extra for n, m in shipped.items()} == {"BATTERY_STATUS": 154, "BATTERY_STATUS_V2": 145,
                                                           "BATTERY_INFO": 26}  # fmt: skip


# --------------------------------------------------------------------------------------------
# Codecs against a pymavlink generated from the corpus


@pytest.fixture(scope="module")
def mavdev(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ModuleType]:
    out = tmp_path_factory.mktemp("mavgen")
    opts = mavgen.Opts(output=str(out / "battgen_mavdev"), wire_protocol="2.0", language="Python3", validate=False)
    with contextlib.redirect_stdout(io.StringIO()):
        assert mavgen.mavgen(opts, [str(CORPUS / "development.xml")])
    sys.path.insert(0, str(out))
    try:
        yield importlib.import_module("battgen_mavdev")
    finally:
        sys.path.remove(str(out))
        sys.modules.pop("battgen_mavdev", None)


def _scalar(t: PrimitiveType) -> st.SearchStrategy[Any]:
    if t.kind is PrimitiveKind.FLOAT:
        return st.floats(width=64 if t.bits == 64 else 32, allow_nan=True, allow_infinity=True)
    lo, hi = (-(1 << (t.bits - 1)), (1 << (t.bits - 1)) - 1) if t.kind is PrimitiveKind.INT else (0, (1 << t.bits) - 1)
    return st.one_of(st.sampled_from([lo, hi, 0]), st.integers(lo, hi))


def _values(f: Field) -> st.SearchStrategy[Any]:
    t = f.type
    if isinstance(t, StringType):
        return st.text(st.characters(min_codepoint=1, max_codepoint=127), max_size=t.capacity or 1)
    if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.capacity:
        return st.lists(_scalar(t.element), min_size=t.capacity, max_size=t.capacity)
    assert isinstance(t, PrimitiveType)
    return _scalar(t)


def _instances(msg: Message, cls: Any) -> st.SearchStrategy[Any]:
    fields = {f.name: st.one_of(st.none(), _values(f)) if f.invalid else _values(f) for f in msg.fields}
    return st.fixed_dictionaries(fields).map(lambda d: cls.from_dict({k: v for k, v in d.items() if v is not None}))


def _same(a: Any, b: Any) -> bool:
    if isinstance(b, bytes) and isinstance(a, str):
        b = b.decode("ascii")
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or a == b
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


SCHEMA = frontend.parse_file(BATTERY_XML)
CASES = [("BATTERY_INFO", BatteryInfo), ("BATTERY_STATUS_V2", BatteryStatusV2), ("BATTERY_STATUS", BatteryStatus)]


@pytest.mark.parametrize(("name", "cls"), CASES, ids=[c[0] for c in CASES])
def test_codec_equals_mavgen_from_corpus(mavdev: ModuleType, name: str, cls: Any) -> None:
    pm_cls = getattr(mavdev, f"MAVLink_{name.lower()}_message")

    @FAST
    @given(_instances(SCHEMA.message(f"mavlink.{name}"), cls), st.integers(0, 255))
    def check(obj: Any, seq: int) -> None:
        data = obj.to_dict()
        args = [
            data[n].encode("ascii") if t == "char" else data[n]
            for n, t in zip(pm_cls.fieldnames, pm_cls.fieldtypes, strict=True)
        ]
        theirs = pm_cls(*args)
        mav = mavdev.MAVLink(None, srcSystem=1, srcComponent=1)
        mav.seq = seq
        frame = theirs.pack(mav)
        assert obj.encode() == bytes(theirs.get_payload())
        assert obj.encode_frame(seq=seq, sysid=1, compid=1) == frame
        parsed = mavdev.MAVLink(None).parse_buffer(frame)
        assert parsed is not None and len(parsed) == 1
        back = runtime.decode_message(frame)
        assert isinstance(back, cls)
        for n in pm_cls.fieldnames:
            assert _same(back.to_dict()[n], getattr(parsed[0], n)), n

    check()


def test_status_flags_json_schema_agrees_with_the_generated_validator() -> None:
    """MAV_BATTERY_STATUS_FLAGS is bits 0-18 plus EXTENDED (2**31): the gap between is refused by both."""
    import jsonschema

    from codegen.backends.json_schema import message_json_schema

    exported = message_json_schema(SCHEMA, SCHEMA.message("mavlink.BATTERY_STATUS_V2"))
    validator = jsonschema.Draft202012Validator(exported)
    for flags, ok in ((0, True), (0x7FFFF, True), (0x80000, False), (0x80000000, True), (0x8007FFFF, True),
                      (0x40000000, False)):  # fmt: skip
        assert validator.is_valid({"status_flags": flags}) is ok, hex(flags)
        assert (BatteryStatusV2(status_flags=flags).validate() == []) is ok, hex(flags)
