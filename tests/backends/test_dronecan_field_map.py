"""The wire layout comment above each DroneCAN codec (codecs/dronecan/field_map.py) against pydronecan's
parse of the same definitions: every bit range a reviewer reads is the one the reference computes, and
every cited line of the DSDL file declares the field it is cited for."""

from __future__ import annotations

import re

import dronecan
import pytest
from conftest import ROOT

from codegen.backends.python.codecs.dronecan.field_map import field_map
from codegen.backends.python.codecs.dronecan.plan import Planner
from codegen.frontends.loader import load
from codegen.ir import Message, SourceFormat

SCHEMA = load([ROOT / "schemas"])
DRONECAN = [m for m in SCHEMA.messages if m.format is SourceFormat.DRONECAN and m.dronecan is not None]
ROW = re.compile(r"#   bits (\S+)\s+(?:void\d+ \(padding\)|\S+ (\w+)).*\(line (\d+)\)$")


def _rows(msg: Message) -> list[tuple[str, str | None, int]]:
    lines = field_map(Planner(SCHEMA, {}), msg)
    assert lines[0].startswith("# Wire layout (")
    rows = []
    for line in lines[1:]:
        if "union tag" in line:
            continue
        found = ROW.match(line)
        assert found, line
        rows.append((found[1], found[2], int(found[3])))
    return rows


def test_every_bundled_dronecan_type_is_mapped_field_by_field() -> None:
    assert len(DRONECAN) >= 8
    for msg in DRONECAN:
        rows = _rows(msg)
        assert [name for _, name, _ in rows if name] == [f.name for f in msg.fields if not f.is_padding]
        text = (ROOT / "schemas" / "dronecan" / msg.location.file).read_text(encoding="utf-8").splitlines()
        for _, name, line in rows:
            declared = text[line - 1].split("#", 1)[0].split()
            assert declared and (name is None or declared[-1] == name), (msg.qualified_name, line, text[line - 1])


@pytest.mark.parametrize(
    "msg", [m for m in DRONECAN if not m.dronecan or not m.dronecan.union], ids=lambda m: m.qualified_name
)
def test_bit_ranges_agree_with_pydronecan(msg: Message) -> None:
    assert msg.dronecan is not None
    name = msg.dronecan.full_name
    if name not in dronecan.TYPENAMES:
        pytest.skip(f"{name} is not among pydronecan's bundled types")
    ref = dronecan.TYPENAMES[name]
    kind = msg.dronecan.kind.name  # a service's halves: pydronecan keeps request_fields and response_fields
    fields = getattr(ref, {"REQUEST": "request_fields", "RESPONSE": "response_fields"}.get(kind, "fields"))
    offset, checked = 0, 0
    for (bits, _, _), ref_field in zip(_rows(msg), fields, strict=True):
        t = ref_field.type
        if t.get_min_bitlen() != t.get_max_bitlen():
            break  # past a field of varying size the comment counts from that field's end
        assert bits == f"{offset}-{offset + t.get_max_bitlen() - 1}", (name, ref_field.name)
        offset += t.get_max_bitlen()
        checked += 1
    assert checked or fields[0].type.get_min_bitlen() != fields[0].type.get_max_bitlen()


def test_battery_info_rows_as_a_reviewer_reads_them() -> None:
    info = next(m for m in DRONECAN if m.qualified_name == "dronecan.uavcan.equipment.power.BatteryInfo")
    lines = field_map(Planner(SCHEMA, {}), info)
    assert lines[1] == "#   bits 0-15      float16 temperature  (line 10)"
    assert lines[8] == "#   bits 112-122   uint11 status_flags  (line 33)"
    assert lines[-1].startswith("#   bits 184-      uint8[<=31] model_name: <=31 x 8 bits, the tail array")
