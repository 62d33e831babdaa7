"""Our MAVLink frontend against pymavlink: its parser (mavparse) and its generated dialect modules.

Wire order, lengths and CRC_EXTRA are computed by codegen.frontends.mavlink.layout on its own,
so agreeing with pymavlink here is a real check, not a copy.
"""

from __future__ import annotations

import contextlib
import importlib
import io
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

import pymavlink
import pytest
from pymavlink.generator import mavparse

from codegen.frontends import mavlink
from codegen.frontends.mavlink.layout import c_type
from codegen.ir import EnumKind, Message, Schema

DIALECTS = Path(pymavlink.__file__).parent / "dialects" / "v20"
ALL_DIALECTS = sorted(p.name for p in DIALECTS.glob("*.xml"))
BATTERY_XML = Path(__file__).resolve().parent.parent / "schemas" / "mavlink" / "battery.xml"
BATTERY_ENUMS = ("MAV_BATTERY_FUNCTION", "MAV_BATTERY_TYPE", "MAV_BATTERY_CHARGE_STATE", "MAV_BATTERY_MODE",
                 "MAV_BATTERY_FAULT", "MAV_BATTERY_STATUS_FLAGS")  # fmt: skip


def _mavxml(path: Path) -> Any:
    with contextlib.redirect_stdout(io.StringIO()):
        return mavparse.MAVXML(str(path), mavparse.PROTOCOL_2_0)


_shared_mavxml = cache(_mavxml)  # read-only uses share one parse per file


def _closure(path: Path, read: Any = _mavxml) -> list[Any]:
    """The file and everything it includes, breadth first, each once (as mavgen expands them)."""
    seen: set[Path] = set()
    queue = [path.resolve()]
    out = []
    while queue:
        p = queue.pop(0)
        if p in seen:
            continue
        seen.add(p)
        x = read(p)
        out.append(x)
        queue.extend((p.parent / inc).resolve() for inc in x.include)
    return out


@cache
def ours(name: str) -> Schema:
    return mavlink.parse_file(DIALECTS / name, root=DIALECTS)


@cache
def theirs(name: str) -> dict[str, Any]:
    """Message name -> mavparse MAVType over the dialect's include closure."""
    return {m.name: m for x in _closure(DIALECTS / name, _shared_mavxml) for m in x.message}


@cache
def generated(name: str) -> ModuleType:
    return importlib.import_module(f"pymavlink.dialects.v20.{Path(name).stem}")


def _mismatches(schema: Schema, reference: dict[str, Any]) -> Iterator[str]:
    for name, m in sorted(reference.items()):
        info = schema.message(f"mavlink.{name}").mavlink
        assert info is not None
        got = (info.msg_id, info.crc_extra, list(info.wire_order), info.base_length, info.max_length)
        want = (m.id, m.crc_extra, m.ordered_fieldnames, m.wire_min_length, m.wire_length)
        if got != want:
            yield f"{name}: ours {got} != mavparse {want}"


def test_common_has_exactly_pymavlinks_messages() -> None:
    schema, reference = ours("common.xml"), theirs("common.xml")
    assert sorted(m.name for m in schema.messages) == sorted(reference)
    assert {m.mavlink.msg_id for m in schema.messages if m.mavlink} == set(generated("common.xml").mavlink_map)
    assert len(reference) > 200  # common + standard + minimal


def test_common_ids_crc_order_lengths_match_mavparse() -> None:
    assert list(_mismatches(ours("common.xml"), theirs("common.xml"))) == []


def test_common_field_types_and_attributes_match_mavparse() -> None:
    bad = []
    for name, m in theirs("common.xml").items():
        msg: Message = ours("common.xml").message(f"mavlink.{name}")
        base = m.base_fields()
        for i, (f, mf) in enumerate(zip(msg.fields, m.fields, strict=True)):
            got = (f.name, c_type(f.type), f.extension, f.unit_text or "", f.enums, f.invalid.text if f.invalid else "")
            units = mf.units[1:-1] if mf.units else ""
            enums = (f"mavlink.{mf.enum}",) if mf.enum else ()
            want = (mf.name, (mf.type, mf.array_length), i >= base, units, enums, mf.invalid)
            if got != want:
                bad.append(f"{name}.{f.name}: {got} != {want}")
            if f.doc != " ".join(mf.description.split()):
                bad.append(f"{name}.{f.name}: doc differs")
    assert bad == []


def test_common_matches_generated_module() -> None:
    """The shipped pymavlink.dialects.v20.common classes, not just the parser."""
    module = generated("common.xml")
    bad = []
    for msg in ours("common.xml").messages:
        info = msg.mavlink
        assert info is not None
        cls = module.mavlink_map[info.msg_id]
        got = (msg.name, info.crc_extra, list(info.wire_order), info.max_length)
        want = (cls.msgname, cls.crc_extra, list(cls.ordered_fieldnames), cls.unpacker.size)
        if got != want:
            bad.append(f"{msg.name}: {got} != {want}")
        types = [c_type(f.type)[0] for f in msg.fields]  # definition order
        by_name = {f.name: f for f in msg.fields}
        lengths = [c_type(by_name[n].type)[1] for n in info.wire_order]  # wire order
        if types != list(cls.fieldtypes) or lengths != list(cls.array_lengths):
            bad.append(f"{msg.name}: field types {types} {lengths} != {cls.fieldtypes} {cls.array_lengths}")
    assert bad == []


def test_common_enums_match_mavparse_and_generated_module() -> None:
    xmls = _closure(DIALECTS / "common.xml")  # fresh objects: merge_enums mutates them
    with contextlib.redirect_stdout(io.StringIO()):
        mavparse.merge_enums(xmls)
    reference = {e.name: e for x in xmls for e in x.enum}
    schema, module = ours("common.xml"), generated("common.xml")
    assert sorted(e.short_name for e in schema.enums) == sorted(reference) == sorted(module.enums)
    for enum in schema.enums:
        ref = reference[enum.short_name]
        entries = [(e.name, e.value) for e in enum.entries]
        assert entries == [(e.name, e.value) for e in ref.entry if not e.end_marker], enum.name
        shipped = [(e.name, v) for v, e in sorted(module.enums[enum.short_name].items())]
        assert entries == [pair for pair in shipped if not pair[0].endswith("_ENUM_END")], enum.name
        if ref.bitmask:
            assert enum.kind is EnumKind.BITMASK, enum.name


@pytest.mark.parametrize("dialect", ALL_DIALECTS)
def test_every_dialect_parses_and_matches(dialect: str) -> None:
    schema = ours(dialect)
    reference = theirs(dialect)
    assert {m.name for m in schema.messages} == set(reference)
    assert list(_mismatches(schema, reference)) == []
    module = generated(dialect)
    for msg in schema.messages:
        assert msg.mavlink is not None
        assert module.mavlink_map[msg.mavlink.msg_id].crc_extra == msg.mavlink.crc_extra, msg.name


def test_battery_xml_equals_common_battery_status() -> None:
    """Our own battery.xml: same wire contract and enum values as pymavlink's bundled common.xml, by both
    parsers. The bundled copy lags mavlink/mavlink: it lacks the invalid markers upstream added to
    time_remaining and voltages_ext (test_mavlink_battery_schema_upstream.py checks against upstream)."""
    (their_battery,) = [m for x in _closure(BATTERY_XML) for m in x.message if m.name == "BATTERY_STATUS"]
    common = theirs("common.xml")["BATTERY_STATUS"]
    shipped = generated("common.xml").MAVLink_battery_status_message
    assert their_battery.crc_extra == common.crc_extra == shipped.crc_extra

    def attrs(m: Any) -> list[tuple[str, ...]]:
        return [(f.name, f.type, str(f.array_length), f.units, f.enum, str(f.instance)) for f in m.fields]

    assert attrs(their_battery) == attrs(common)
    lagging = {f.name: (f.invalid, g.invalid) for f, g in zip(their_battery.fields, common.fields, strict=True)}
    assert {k: v for k, v in lagging.items() if v[0] != v[1]} == {
        "time_remaining": ("0", ""),
        "voltages_ext": ("[0]", ""),
    }
    schema = mavlink.parse_file(BATTERY_XML, root=BATTERY_XML.parent)
    mine, reference = schema.message("mavlink.BATTERY_STATUS"), ours("common.xml").message("mavlink.BATTERY_STATUS")
    assert mine.mavlink is not None and reference.mavlink is not None
    assert mine.mavlink.crc_extra == shipped.crc_extra
    assert (mine.mavlink.msg_id, mine.mavlink.wire_order, mine.mavlink.base_length, mine.mavlink.max_length) == (
        reference.mavlink.msg_id, reference.mavlink.wire_order, reference.mavlink.base_length,
        reference.mavlink.max_length,
    )  # fmt: skip
    strip = [(f.name, f.type, f.unit, f.unit_text, f.enums, f.extension, f.annotations) for f in mine.fields]
    assert strip == [
        (f.name, f.type, f.unit, f.unit_text, f.enums, f.extension, f.annotations) for f in reference.fields
    ]
    assert sorted(e.short_name for e in schema.enums) == sorted(BATTERY_ENUMS)
    for enum in schema.enums:
        if enum.short_name == "MAV_BATTERY_STATUS_FLAGS":
            continue  # development.xml, not in pymavlink's common.xml
        assert [(e.name, e.value) for e in enum.entries] == [
            (e.name, e.value) for e in ours("common.xml").enum(enum.name).entries
        ]
        assert enum.kind is ours("common.xml").enum(enum.name).kind
