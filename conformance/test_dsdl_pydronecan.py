"""Our DSDL frontend against pydronecan's parser and encoder, on the same definition trees.

* The whole dsdl_specs tree of the installed ``dronecan`` package: every type's signature,
  normalized definition, bit lengths, data type id, union flag, fields and constants.
* Tail array optimisation: the maximal instance of every structure, packed by pydronecan's own
  encoder with and without TAO, is exactly max_bitlen_tao / max_bitlen bits long.
* Our bundled schemas/dronecan: each type equals pydronecan's definition of the same name.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest

from codegen.frontends import dsdl
from codegen.ir import ArrayType, CompositeType, DronecanKind, FieldType, Message, PrimitiveKind, PrimitiveType, Schema

dronecan = pytest.importorskip("dronecan")
from dronecan import dsdl as pydsdl  # noqa: E402
from dronecan import transport  # noqa: E402
from shared_data import SHARED, missing  # noqa: E402

SPECS = Path(os.path.dirname(dronecan.__file__)) / "dsdl_specs"
BUNDLED = Path(__file__).resolve().parents[1] / "schemas" / "dronecan"


def _reference(root: Path) -> dict[str, Any]:
    dirs = sorted(str(p) for p in root.iterdir() if p.is_dir())
    return {t.full_name: t for t in pydsdl.parse_namespaces(dirs)}


@pytest.fixture(scope="module")
def reference() -> dict[str, Any]:
    return _reference(SPECS)


@pytest.fixture(scope="module")
def ours() -> Schema:
    return dsdl.parse_dir(SPECS)


@pytest.fixture(scope="module")
def bundled() -> Schema:
    return dsdl.parse_dir(BUNDLED)


# --------------------------------------------------------------------------------------------
# pydronecan objects -> comparable tuples (and the same for ours)

_REF_KINDS = {
    pydsdl.PrimitiveType.KIND_BOOLEAN: "bool",
    pydsdl.PrimitiveType.KIND_UNSIGNED_INT: "uint",
    pydsdl.PrimitiveType.KIND_SIGNED_INT: "int",
    pydsdl.PrimitiveType.KIND_FLOAT: "float",
}


def _ref_type(t: Any) -> tuple[Any, ...]:
    if t.category == t.CATEGORY_PRIMITIVE:
        cast = "saturated" if t.cast_mode == t.CAST_MODE_SATURATED else "truncated"
        return ("prim", _REF_KINDS[t.kind], t.bitlen, cast)
    if t.category == t.CATEGORY_VOID:
        return ("void", t.bitlen)
    if t.category == t.CATEGORY_ARRAY:
        return ("array", _ref_type(t.value_type), t.max_size, t.mode == t.MODE_DYNAMIC)
    return ("ref", "dronecan." + t.full_name)


def _our_type(t: FieldType) -> tuple[Any, ...]:
    if isinstance(t, PrimitiveType):
        if t.kind is PrimitiveKind.VOID:
            return ("void", t.bits)
        return ("prim", t.kind.value, t.bits, t.cast.value)
    if isinstance(t, ArrayType):
        return ("array", _our_type(t.element), t.capacity, t.dynamic)
    assert isinstance(t, CompositeType)
    return ("ref", t.name)


def _halves(t: Any) -> list[tuple[str, DronecanKind, list[Any], list[Any], bool, int, int]]:
    if t.kind == t.KIND_MESSAGE:
        return [("", DronecanKind.MESSAGE, t.fields, t.constants, t.union, t.get_min_bitlen(), t.get_max_bitlen())]
    return [
        (".Request", DronecanKind.REQUEST, t.request_fields, t.request_constants, t.request_union,
         t.get_min_bitlen_request(), t.get_max_bitlen_request()),
        (".Response", DronecanKind.RESPONSE, t.response_fields, t.response_constants, t.response_union,
         t.get_min_bitlen_response(), t.get_max_bitlen_response()),
    ]  # fmt: skip


def _assert_same(t: Any, schema: Schema) -> None:
    for suffix, kind, fields, constants, union, min_bits, max_bits in _halves(t):
        m = schema.message(f"dronecan.{t.full_name}{suffix}")
        info = m.dronecan
        assert info is not None
        assert info.full_name == t.full_name
        assert info.kind is kind
        assert info.signature == t.get_data_type_signature()
        assert info.normalized_definition == t.get_dsdl_signature_source_definition()
        assert info.data_type_id == t.default_dtid
        assert info.union == union
        assert (info.min_bitlen, info.max_bitlen) == (min_bits, max_bits)
        assert [(f.name or "", _our_type(f.type)) for f in m.fields] == [
            ("" if f.type.category == f.type.CATEGORY_VOID else f.name, _ref_type(f.type)) for f in fields
        ]
        assert [(c.name, c.value, _our_type(c.type)) for c in m.constants if isinstance(c.type, PrimitiveType)] == [
            (c.name, c.value, _ref_type(c.type)) for c in constants
        ]
        assert all(type(ours.value) is type(ref.value) or ref.type.kind == ref.type.KIND_BOOLEAN
                   for ours, ref in zip(m.constants, constants, strict=True))  # fmt: skip


def test_every_reference_type_is_parsed(reference: dict[str, Any], ours: Schema) -> None:
    assert len(reference) >= 140
    expected = set()
    for name, t in reference.items():
        expected |= {f"dronecan.{name}"} if t.kind == t.KIND_MESSAGE else {f"dronecan.{name}.Request",
                                                                            f"dronecan.{name}.Response"}  # fmt: skip
    assert {m.qualified_name for m in ours.messages} == expected
    assert len(ours.sources) == len(reference)


def test_every_type_matches_pydronecan(reference: dict[str, Any], ours: Schema) -> None:
    for t in reference.values():
        _assert_same(t, ours)


def test_overridden_signatures_are_honoured(reference: dict[str, Any], ours: Schema) -> None:
    overridden = [t for t in reference.values() if getattr(t, "override_signature", None) is not None]
    assert overridden, "the reference tree is expected to use OVERRIDE_SIGNATURE"
    for t in overridden:
        name = f"dronecan.{t.full_name}" + ("" if t.kind == t.KIND_MESSAGE else ".Request")
        info = ours.message(name).dronecan
        assert info is not None and info.signature == t.get_data_type_signature()


# --------------------------------------------------------------------------------------------
# Tail array optimisation against pydronecan's encoder


def _fill_max(value: Any, tao: bool) -> None:
    """Grow ``value`` to its longest encoding in a context with (or without) TAO."""
    if isinstance(value, transport.CompoundValue):
        names = list(value._fields)
        if value._is_union:
            lengths = []
            for name in names:
                value.__dict__["_union_field"] = name
                _fill_max(value._fields[name], tao)
                lengths.append(len(value._pack(tao)))
            value.__dict__["_union_field"] = names[lengths.index(max(lengths))]
        else:
            for i, name in enumerate(names):
                _fill_max(value._fields[name], tao and i == len(names) - 1)
    elif isinstance(value, transport.ArrayValue):
        t = value._type
        dropped_prefix = t.mode == t.MODE_DYNAMIC and tao and t.value_type.get_min_bitlen() >= 8
        if t.mode == t.MODE_DYNAMIC:
            while len(value) < t.max_size:
                value.append(value.new_item() if isinstance(t.value_type, pydsdl.CompoundType) else 0)
        for i in range(len(value)):
            item = value[i]
            _fill_max(item, False if dropped_prefix else tao and i == len(value) - 1)


def _encoded_bits(t: Any, mode: str | None, tao: bool) -> int:
    value = transport.CompoundValue(t, _mode=mode)
    _fill_max(value, tao)
    return len(value._pack(tao))


def _assert_wire_lengths(t: Any, schema: Schema) -> None:
    modes = [(None, "")] if t.kind == t.KIND_MESSAGE else [("request", ".Request"), ("response", ".Response")]
    for mode, suffix in modes:
        info = schema.message(f"dronecan.{t.full_name}{suffix}").dronecan
        assert info is not None
        assert _encoded_bits(t, mode, tao=False) == info.max_bitlen, t.full_name
        assert _encoded_bits(t, mode, tao=True) == info.max_bitlen_tao, t.full_name


def test_tao_lengths_match_pydronecan_encoder(reference: dict[str, Any], ours: Schema) -> None:
    tao_types = 0
    for t in reference.values():
        _assert_wire_lengths(t, ours)
        for m in [ours.message(n) for n in _names(t)]:
            assert m.dronecan is not None and m.dronecan.min_bitlen_tao == m.dronecan.min_bitlen
            tao_types += m.dronecan.max_bitlen_tao < m.dronecan.max_bitlen
    assert tao_types > 20


def _names(t: Any) -> list[str]:
    base = f"dronecan.{t.full_name}"
    return [base] if t.kind == t.KIND_MESSAGE else [f"{base}.Request", f"{base}.Response"]


# --------------------------------------------------------------------------------------------
# Our bundled definitions


BUNDLED_TYPES = [
    "uavcan.Timestamp",
    "uavcan.equipment.power.BatteryInfo",
    "uavcan.equipment.power.CircuitStatus",
    "uavcan.equipment.power.PrimaryPowerSupplyStatus",
    "ardupilot.equipment.power.BatteryInfoAux",
    "ardupilot.equipment.power.BatteryContinuous",
    "ardupilot.equipment.power.BatteryPeriodic",
    "ardupilot.equipment.power.BatteryCells",
    "ardupilot.equipment.power.BatteryTag",
    "cuav.equipment.power.CBAT",
]


# dronecan/DSDL as upstream has it today (February 2026: BatteryInfo's STATE_OF_CHARGE_UNKNOWN, which the dronecan
# package's copy predates), read by pydronecan's own parser
UPSTREAM_DSDL = SHARED / "corpus" / "realworld3b" / "dsdl" / "DSDL"


@pytest.fixture(scope="module")
def upstream_today() -> dict[str, Any]:
    if not UPSTREAM_DSDL.is_dir():
        missing("dronecan/DSDL (corpus/realworld3b/dsdl/DSDL)")
    return _reference(UPSTREAM_DSDL)


def test_bundled_schemas_equal_upstream_definitions(upstream_today: dict[str, Any], bundled: Schema) -> None:
    assert sorted(m.dronecan.full_name for m in bundled.messages if m.dronecan) == sorted(BUNDLED_TYPES)
    for name in BUNDLED_TYPES:
        _assert_same(upstream_today[name], bundled)
        _assert_wire_lengths(upstream_today[name], bundled)


def test_bundled_battery_info_knows_the_unknown_charge(bundled: Schema, upstream_today: dict[str, Any]) -> None:
    """The constant pydronecan's package lacks: ours has it, a sentinel of state_of_charge_pct only."""
    ref = upstream_today["uavcan.equipment.power.BatteryInfo"]
    assert ("STATE_OF_CHARGE_UNKNOWN", 127) in [(c.name, c.value) for c in ref.constants]
    info = bundled.message("dronecan.uavcan.equipment.power.BatteryInfo")
    fields = {f.name: f for f in info.fields}
    assert fields["state_of_charge_pct"].invalid is not None and fields["state_of_charge_pct"].invalid.value == 127
    assert fields["state_of_charge_pct_stdev"].invalid is None
    assert [e.name.rsplit(".", 1)[-1] for e in info.enums] == ["STATUS_FLAG"]  # the two sentinels are no enum


def test_bundled_schemas_parse_with_pydronecan(bundled: Schema, upstream_today: dict[str, Any]) -> None:
    """pydronecan reads our files too, and finds the same signatures as for upstream's."""
    ours_by_pydronecan = _reference(BUNDLED)
    assert sorted(ours_by_pydronecan) == sorted(BUNDLED_TYPES)
    for name, t in ours_by_pydronecan.items():
        assert t.get_data_type_signature() == upstream_today[name].get_data_type_signature()
        m: Message = bundled.message(f"dronecan.{name}")
        assert m.dronecan is not None and m.dronecan.signature == t.get_data_type_signature()
