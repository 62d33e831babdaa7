"""The Cyphal frontend against pydsdl on upstream's regulated data types (../shared/corpus/cyphal/), and
our own battery definitions (schemas/cyphal/) against upstream's: the same layouts, extents and port ids."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import pydsdl
import pytest
from shared_data import shared

from codegen.frontends import cyphal
from codegen.frontends.cyphal.build import type_name
from codegen.ir import CyphalKind, Schema

ROOT = Path(__file__).resolve().parents[1]
CORPUS = shared("corpus", "cyphal")
OURS = ROOT / "schemas" / "cyphal"
needs_corpus = pytest.mark.skipif(not (CORPUS / "reg").is_dir(), reason="the Cyphal corpus is not present")


@cache
def _reference() -> list[pydsdl.CompositeType]:
    spaces = [CORPUS / "uavcan", CORPUS / "reg"]
    return [t for s in spaces for t in pydsdl.read_namespace(s, [o for o in spaces if o != s])]


@cache
def _ours() -> Schema:
    return cyphal.parse_dir(CORPUS)


def _halves(t: pydsdl.CompositeType) -> list[tuple[str, pydsdl.CompositeType]]:
    if isinstance(t, pydsdl.ServiceType):
        base = type_name(t)
        return [(base + ".Request", t.request_type), (base + ".Response", t.response_type)]
    return [(type_name(t), t)]


@needs_corpus
def test_every_regulated_type_reads_with_pydsdls_bit_lengths_extents_and_port_ids() -> None:
    schema = _ours()
    reference = _reference()
    assert len(reference) > 200
    seen = 0
    for t in reference:
        for name, part in _halves(t):
            info = schema.message(name).cyphal
            assert info is not None
            inner = part.inner_type if isinstance(part, pydsdl.DelimitedType) else part
            assert (info.min_bitlen, info.max_bitlen) == (inner.bit_length_set.min, inner.bit_length_set.max), name
            assert info.extent == part.extent, name
            assert info.sealed is not isinstance(part, pydsdl.DelimitedType), name
            assert info.fixed_port_id == t.fixed_port_id, name
            assert (info.major, info.minor) == (t.version.major, t.version.minor)
            assert info.union is isinstance(inner, pydsdl.UnionType)
            assert [f.name for f in schema.message(name).fields] == [
                "" if isinstance(f, pydsdl.PaddingField) else f.name for f in inner.fields
            ]
            seen += 1
    assert seen == len(schema.messages)


@needs_corpus
def test_services_are_two_halves_with_the_services_port_id() -> None:
    schema = _ours()
    request = schema.message("cyphal.uavcan.node.ExecuteCommand_1_3.Request")
    response = schema.message("cyphal.uavcan.node.ExecuteCommand_1_3.Response")
    assert request.cyphal is not None and response.cyphal is not None
    assert request.cyphal.kind is CyphalKind.REQUEST and response.cyphal.kind is CyphalKind.RESPONSE
    assert request.cyphal.fixed_port_id == response.cyphal.fixed_port_id == 435


@needs_corpus
def test_our_battery_definitions_match_upstreams_layouts() -> None:
    """schemas/cyphal/ is our own text of the battery types; pydsdl must read it as upstream's."""
    ours = cyphal.parse_dir(OURS)
    upstream = _ours()
    assert len(ours.messages) == 19
    for msg in ours.messages:
        theirs = upstream.message(msg.qualified_name)
        assert msg.cyphal is not None and theirs.cyphal is not None
        assert (msg.cyphal.min_bitlen, msg.cyphal.max_bitlen, msg.cyphal.extent, msg.cyphal.sealed) == (
            theirs.cyphal.min_bitlen,
            theirs.cyphal.max_bitlen,
            theirs.cyphal.extent,
            theirs.cyphal.sealed,
        )
        assert [(f.name, f.type, f.unit) for f in msg.fields] == [(f.name, f.type, f.unit) for f in theirs.fields]
        assert [(c.name, c.value) for c in msg.constants] == [(c.name, c.value) for c in theirs.constants]


@needs_corpus
def test_units_and_sentinels_of_the_battery_types() -> None:
    schema = _ours()
    status = schema.message("cyphal.reg.udral.service.battery.Status_0_2")
    assert status.field("available_charge").unit is not None and status.field("available_charge").unit.symbol == "C"
    assert status.field("temperature_min_max").unit.symbol == "K"  # type: ignore[union-attr]
    assert status.field("cell_voltages").unit.symbol == "V"  # type: ignore[union-attr]
    assert status.cyphal is not None and status.cyphal.extent == 600 * 8 and not status.cyphal.sealed
    volt = schema.message("cyphal.uavcan.si.unit.voltage.Scalar_1_0").field("volt")
    assert volt.invalid is not None and volt.invalid.is_nan
    stamp = schema.message("cyphal.uavcan.time.SynchronizedTimestamp_1_0").field("microsecond")
    assert stamp.invalid is not None and stamp.invalid.value == 0 and stamp.unit.symbol == "us"  # type: ignore[union-attr]
    error = schema.message("cyphal.reg.udral.service.battery.Error_0_1")
    assert {e.name: e.value for e in error.enums[0].entries}["TEMPERATURE_COLD"] == 101
    soh = schema.message("cyphal.reg.udral.service.battery.Parameters_0_3").field("state_of_health_pct")
    assert soh.unit is not None and soh.unit.symbol == "%"


def test_reg_drone_is_read_as_reg_udral(tmp_path: Path) -> None:
    space = tmp_path / "reg" / "drone" / "physics" / "electricity"
    space.mkdir(parents=True)
    (tmp_path / "uavcan" / "si" / "unit" / "voltage").mkdir(parents=True)
    (tmp_path / "uavcan" / "si" / "unit" / "voltage" / "Scalar.1.0.dsdl").write_text("float32 volt\n@sealed\n")
    (space / "Voltage.0.1.dsdl").write_text("uavcan.si.unit.voltage.Scalar.1.0 voltage\n@sealed\n")
    schema = cyphal.parse_dir(tmp_path)
    msg = schema.message("cyphal.reg.udral.physics.electricity.Voltage_0_1")
    assert msg.cyphal is not None and msg.cyphal.full_name == "reg.drone.physics.electricity.Voltage"
    assert msg.cyphal.alias_of == "reg.udral.physics.electricity.Voltage"


def test_a_bad_definition_is_a_located_error(tmp_path: Path) -> None:
    from codegen.errors import BattgenError

    (tmp_path / "ns").mkdir()
    (tmp_path / "ns" / "Bad.1.0.dsdl").write_text("uint8 a\nfloat99 b\n@sealed\n")
    with pytest.raises(BattgenError, match=r"ns/Bad.1.0.dsdl:2: expected valid Cyphal DSDL"):
        cyphal.parse_dir(tmp_path)
