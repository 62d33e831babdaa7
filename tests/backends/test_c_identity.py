"""The identities the C headers publish equal the references': every DroneCAN type's data type
signature and id as pydronecan computes them, every MAVLink message's id and CRC_EXTRA as pymavlink's
generated dialects give them."""

from __future__ import annotations

import re

import pytest

from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.backends.c.types import type_name
from codegen.frontends.loader import load
from codegen.ir import SourceFormat

GENERATED = project_root() / "generated" / "c"
SCHEMA = load([bundled_schemas()])


def _defines(rel: str) -> dict[str, int]:
    text = (GENERATED / rel).read_text(encoding="utf-8").replace("\\\n", " ")
    return {m[1]: int(m[2], 0) for m in re.finditer(r"#define (\w+)\s+(0x[0-9A-F]+|\d+)(?:u|ULL)?\b", text)}


@pytest.mark.parametrize("qualified", [m.qualified_name for m in SCHEMA.messages if m.format is SourceFormat.DRONECAN])
def test_dronecan_signature_and_id_equal_pydronecan(qualified: str) -> None:
    dronecan = pytest.importorskip("dronecan")
    full = qualified.removeprefix("dronecan.")
    ref = dronecan.TYPENAMES[full]
    defines = _defines(qualified.replace(".", "/") + ".h")
    prefix = type_name(qualified).upper()
    assert defines[prefix + "_DATA_TYPE_SIGNATURE"] == ref.get_data_type_signature()
    assert defines.get(prefix + "_DATA_TYPE_ID") == ref.default_dtid


@pytest.mark.parametrize("qualified", [m.qualified_name for m in SCHEMA.messages if m.format is SourceFormat.MAVLINK])
def test_mavlink_id_and_crc_extra_equal_pymavlink(qualified: str) -> None:
    """pymavlink's own parser (mavgen's front half) reads the same XML and computes id and CRC_EXTRA."""
    from pymavlink.generator import mavparse

    messages = {
        m.name: m
        for path in sorted((bundled_schemas() / "mavlink").glob("*.xml"))
        for m in mavparse.MAVXML(str(path), mavparse.PROTOCOL_2_0).message
    }
    ref = messages[qualified.removeprefix("mavlink.")]
    defines = _defines(qualified.replace(".", "/") + ".h")
    prefix = type_name(qualified).upper()
    assert defines[prefix + "_MSG_ID"] == ref.id
    assert defines[prefix + "_CRC_EXTRA"] == ref.crc_extra
    assert defines[prefix + "_MAX_LENGTH"] == ref.wire_length
