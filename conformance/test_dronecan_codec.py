"""Generated DroneCAN codecs against pydronecan's encoder and decoder, on the same random values.

For every type of our bundled schemas/dronecan and of the whole dsdl_specs tree the ``dronecan``
package ships (generated into a temporary package): hypothesis draws plain values representable
in the type (float16 edge cases, NaN, infinities, out-of-range values of saturated and truncated
types, empty and full arrays, every union branch); both our object and a pydronecan object are
filled from them; the encodings, with and without tail array optimisation, must be identical
bytes, and both decoders must read those bytes to equal values. Also: data type ids, signatures
and the transfer CRC against pydronecan's own computation.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import math
import os
import struct
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from codegen.backends.python import naming
from codegen.backends.python.writer import generate
from codegen.frontends import dsdl
from codegen.ir import (
    ArrayType,
    CompositeType,
    DronecanKind,
    FieldType,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Schema,
)

dronecan = pytest.importorskip("dronecan")
from dronecan import dsdl as pydsdl  # noqa: E402
from dronecan import transport  # noqa: E402

SPECS = Path(os.path.dirname(dronecan.__file__)) / "dsdl_specs"
BUNDLED = Path(__file__).resolve().parents[1] / "schemas" / "dronecan"

F16_EDGES = [
    0.0,
    -0.0,
    1.0,
    -2.5,
    65504.0,
    -65504.0,
    65519.9,
    65520.0,
    1e6,
    -1e6,
    6.103515625e-05,
    6.1e-05,
    5.960464477539063e-08,
    2.9802322387695312e-08,
    2.98e-08,
    1e-9,
    0.1,
    1.00048828125,
    2049.0,
    math.nan,
    -math.nan,
    math.inf,
    -math.inf,
]


# --------------------------------------------------------------------------------------------
# Fixtures: our schemas, the generated packages, pydronecan's types


class Side:
    """One schema tree: our IR and generated package, and pydronecan's types for the same files."""

    def __init__(self, root: Path, out: Path, package: str) -> None:
        self.schema: Schema = dsdl.parse_dir(root)
        generate(self.schema, out / package)
        self.package = package
        dirs = sorted(str(p) for p in root.iterdir() if p.is_dir())
        self.reference = {t.full_name: t for t in pydsdl.parse_namespaces(dirs)}
        self.by_name = {m.qualified_name: m for m in self.schema.messages}
        self.draw = Draw(self)
        self.exact = Draw(self, canonical=True)  # values the types hold exactly: decode(encode(x)) == x

    def cls(self, msg: Message) -> Any:
        module = importlib.import_module(f"{self.package}.{naming.module_path(msg)}")
        return getattr(module, naming.class_name(msg))

    def ref_type(self, msg: Message) -> Any:
        assert msg.dronecan is not None
        return self.reference[msg.dronecan.full_name]

    def ref_new(self, msg: Message) -> Any:
        assert msg.dronecan is not None
        mode = {DronecanKind.REQUEST: "request", DronecanKind.RESPONSE: "response"}.get(msg.dronecan.kind)
        return transport.CompoundValue(self.ref_type(msg), _mode=mode)


_PYDRONECAN_CAST = transport.cast


def spec_cast(value: Any, dtype: Any) -> Any:
    """pydronecan's cast, but a saturated float keeps infinity, as the DSDL v0 specification says
    ("infinity will be preserved") and libuavcan does; pydronecan's setter alone clamps it (the one
    divergence, pinned in test_dronecan_float_casts.py)."""
    saturated = dtype.cast_mode == pydsdl.PrimitiveType.CAST_MODE_SATURATED
    if dtype.kind == pydsdl.PrimitiveType.KIND_FLOAT and saturated and math.isinf(value):
        return value
    return _PYDRONECAN_CAST(value, dtype)


@pytest.fixture(scope="module", autouse=True)
def _spec_infinity() -> Iterator[None]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(transport, "cast", spec_cast)
        yield


@pytest.fixture(scope="module")
def sides(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Side]]:
    out = tmp_path_factory.mktemp("dronecan_codec")
    sys.path.insert(0, str(out))
    try:
        yield {"bundled": Side(BUNDLED, out, "dc_bundled"), "specs": Side(SPECS, out, "dc_specs")}
        print(f"\nDroneCAN checks: {COUNTS}")
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] in ("dc_bundled", "dc_specs")]:
            del sys.modules[name]


def _names(root: Path) -> list[str]:
    return [m.qualified_name for m in dsdl.parse_dir(root).messages]


# --------------------------------------------------------------------------------------------
# Plain values: drawn from the IR type, poured into both objects, read back from both


def _prim_strategy(t: PrimitiveType, in_bytes: bool, canonical: bool = False) -> st.SearchStrategy[Any]:
    """Values for a primitive; ``canonical`` ones are those the type holds exactly (decode gives them back)."""
    if t.kind is PrimitiveKind.BOOL:
        return st.booleans()
    if t.kind is PrimitiveKind.UINT:
        top = (1 << t.bits) - 1
        if in_bytes or canonical:
            return st.integers(0, top)
        return st.one_of(st.integers(0, top), st.sampled_from([0, top]), st.integers(-(1 << t.bits), 1 << (t.bits + 1)))
    if t.kind is PrimitiveKind.INT:
        lo, hi = -(1 << (t.bits - 1)), (1 << (t.bits - 1)) - 1
        if canonical:
            return st.one_of(st.integers(lo, hi), st.sampled_from([lo, hi, -1]))
        return st.one_of(st.integers(lo, hi), st.sampled_from([lo, hi, -1]), st.integers(2 * lo, 2 * hi + 2))
    if canonical:  # every value a float holds, infinity included in both cast modes
        if t.bits == 16:
            return st.integers(0, 0xFFFF).map(lambda b: struct.unpack("<e", struct.pack("<H", b))[0])
        return st.floats(width=t.bits)  # type: ignore[arg-type]
    if t.bits == 16:
        return st.one_of(st.sampled_from(F16_EDGES), st.floats(width=32), st.floats(-70000.0, 70000.0))
    if t.bits == 32:
        return st.one_of(st.floats(width=32), st.floats(), st.sampled_from([3.4028235e38, -3.5e38, 1e-45, math.nan]))
    return st.floats()


class Draw:
    def __init__(self, side: Side, canonical: bool = False) -> None:
        self.side = side
        self.canonical = canonical
        self.cache: dict[str, st.SearchStrategy[Any]] = {}

    def message(self, msg: Message) -> st.SearchStrategy[Any]:
        name = msg.qualified_name
        if name not in self.cache:
            fields = [f for f in msg.fields if not f.is_padding]
            assert msg.dronecan is not None
            if msg.dronecan.union:
                self.cache[name] = st.one_of([self.branch(f.name, f.type) for f in fields])
            else:
                self.cache[name] = st.fixed_dictionaries({f.name: self.field(f.type) for f in fields})
        return self.cache[name]

    def branch(self, name: str, t: FieldType) -> st.SearchStrategy[Any]:
        def wrap(value: Any) -> dict[str, Any]:
            return {"_branch": name, name: value}

        return self.field(t).map(wrap)

    def field(self, t: FieldType) -> st.SearchStrategy[Any]:
        if isinstance(t, PrimitiveType):
            return _prim_strategy(t, False, self.canonical)
        if isinstance(t, CompositeType):
            return st.deferred(lambda: self.message(self.side.by_name[t.name]))
        assert isinstance(t, ArrayType) and t.capacity is not None
        cap = t.capacity
        u8 = isinstance(t.element, PrimitiveType) and t.element.kind is PrimitiveKind.UINT and t.element.bits == 8
        if isinstance(t.element, PrimitiveType):
            elem = _prim_strategy(t.element, True, self.canonical)
        else:
            elem = self.field(t.element)
        if not t.dynamic:
            return st.lists(elem, min_size=cap, max_size=cap)
        if u8:
            return st.one_of(st.binary(max_size=cap), st.binary(min_size=cap, max_size=cap)).map(list)
        full = st.lists(elem, min_size=cap, max_size=cap) if cap <= 40 else st.lists(elem, max_size=cap)
        return st.one_of(st.lists(elem, max_size=min(cap, 6)), full)


def fill_ref(side: Side, obj: Any, msg: Message, plain: dict[str, Any]) -> None:
    """Pour plain values into a pydronecan CompoundValue."""
    names = [plain["_branch"]] if "_branch" in plain else [f.name for f in msg.fields if not f.is_padding]
    for name in names:
        f = msg.field(name)
        value = plain[name]
        if isinstance(f.type, PrimitiveType):
            setattr(obj, name, value)
        elif isinstance(f.type, CompositeType):
            fill_ref(side, getattr(obj, name), side.by_name[f.type.name], value)
        else:
            assert isinstance(f.type, ArrayType)
            elem = f.type.element
            if isinstance(elem, PrimitiveType):
                setattr(obj, name, value)
                continue
            assert isinstance(elem, CompositeType)
            array = getattr(obj, name)
            sub = side.by_name[elem.name]
            if f.type.dynamic:
                for item_plain in value:
                    item = array.new_item()
                    fill_ref(side, item, sub, item_plain)
                    array.append(item)
            else:
                for i, item_plain in enumerate(value):
                    fill_ref(side, array[i], sub, item_plain)


def _attrs(cls: Any) -> dict[str, str]:
    return {f.metadata["name"]: f.name for f in dataclasses.fields(cls) if "name" in f.metadata}


def build_ours(side: Side, msg: Message, plain: dict[str, Any]) -> Any:
    """Our object for plain values; a union is constructed by its one branch, as a user would."""
    cls = side.cls(msg)
    attrs = _attrs(cls)
    if "_branch" in plain:
        branch = plain["_branch"]
        obj = cls(**{attrs[branch]: _ours_value(side, msg.field(branch).type, plain[branch])})
        assert obj.union_field == branch
        return obj
    obj = cls()
    for name in [f.name for f in msg.fields if not f.is_padding]:
        f = msg.field(name)
        setattr(obj, attrs[name], _ours_value(side, f.type, plain[name]))
    return obj


def _ours_value(side: Side, t: FieldType, value: Any) -> Any:
    if isinstance(t, PrimitiveType):
        return value
    if isinstance(t, CompositeType):
        return build_ours(side, side.by_name[t.name], value)
    assert isinstance(t, ArrayType)
    elem = t.element
    if isinstance(elem, PrimitiveType) and elem.kind is PrimitiveKind.UINT and elem.bits == 8:
        return bytes(value)
    return [_ours_value(side, elem, v) for v in value]


def plain_ref(side: Side, obj: Any, msg: Message) -> Any:
    """Comparable plain data of a decoded pydronecan value."""
    assert msg.dronecan is not None
    names = [f.name for f in msg.fields if not f.is_padding]
    if msg.dronecan.union:
        names = [transport.get_active_union_field(obj)]
    out = {}
    for name in names:
        t = msg.field(name).type
        out[name] = _plain_ref_value(side, t, getattr(obj, name))
    return (names[0], out) if msg.dronecan.union else out


def _plain_ref_value(side: Side, t: FieldType, value: Any) -> Any:
    if isinstance(t, PrimitiveType):
        return _norm(value)
    if isinstance(t, CompositeType):
        return plain_ref(side, value, side.by_name[t.name])
    assert isinstance(t, ArrayType)
    return [_plain_ref_value(side, t.element, value[i]) for i in range(len(value))]


def plain_ours(side: Side, obj: Any, msg: Message) -> Any:
    assert msg.dronecan is not None
    attrs = _attrs(type(obj))
    names = [f.name for f in msg.fields if not f.is_padding]
    if msg.dronecan.union:
        names = [n for n in names if n == obj.union_field]
    out = {}
    for name in names:
        out[name] = _plain_ours_value(side, msg.field(name).type, getattr(obj, attrs[name]))
    return (names[0], out) if msg.dronecan.union else out


def _plain_ours_value(side: Side, t: FieldType, value: Any) -> Any:
    if isinstance(t, PrimitiveType):
        return _norm(value)
    if isinstance(t, CompositeType):
        return plain_ours(side, value, side.by_name[t.name])
    assert isinstance(t, ArrayType)
    return [_plain_ours_value(side, t.element, v) for v in value]


def _norm(value: Any) -> Any:
    """NaN compares equal to NaN (with its sign); -0.0 keeps its sign."""
    if isinstance(value, float):
        if math.isnan(value):
            return ("nan", math.copysign(1.0, value))
        return (value, math.copysign(1.0, value))
    return value


def check_roundtrip(side: Side, msg: Message, plain: dict[str, Any], exact: bool = False) -> None:
    """Our bytes equal pydronecan's for the same values, both decoders agree, and plain data round-trips;
    for ``exact`` values (those the type holds exactly) also ``decode(encode(x)) == x``."""
    ref = side.ref_new(msg)
    fill_ref(side, ref, msg, plain)
    ours = build_ours(side, msg, plain)
    cls = side.cls(msg)
    data = ours.to_dict()
    assert cls.from_dict(data) == ours, msg.qualified_name
    assert cls.from_dict(json.loads(json.dumps(data))) == ours, msg.qualified_name
    COUNTS["to_dict"] += 1
    for tao in (True, False):
        expected = bytes(transport.bytes_from_bits(ref._pack(tao)))
        got = ours.encode(tao=tao)
        assert got == expected, f"{msg.qualified_name} tao={tao}: {got.hex()} != {expected.hex()} for {plain!r}"
        decoded = side.cls(msg).decode(expected, tao=tao)
        back = side.ref_new(msg)
        back._unpack(transport.bits_from_bytes(got), tao)
        assert plain_ours(side, decoded, msg) == plain_ref(side, back, msg), f"{msg.qualified_name} tao={tao}"
        assert decoded.encode(tao=tao) == expected
        COUNTS["encode"] += 1
        if exact:
            assert decoded == ours, f"{msg.qualified_name} tao={tao}: decode(encode(x)) != x for {plain!r}"
            COUNTS["decode"] += 1


# the fuzzing budget's switch (tests/fuzz/budget.py): BATTGEN_FUZZ=long tries far more values per type
LONG = os.environ.get("BATTGEN_FUZZ", "") == "long"


def _examples(ci: int) -> int:
    override = os.environ.get("BATTGEN_FUZZ_EXAMPLES")
    return int(override) if override else ci * 40 if LONG else ci


# checks made in this session, printed when the module's packages are torn down (pytest -s)
COUNTS = {"to_dict": 0, "encode": 0, "decode": 0}


SWEEP = settings(
    max_examples=_examples(10),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


@pytest.mark.parametrize("name", _names(SPECS))
@SWEEP
@given(data=st.data())
def test_specs_type_matches_pydronecan(sides: dict[str, Side], name: str, data: st.DataObject) -> None:
    side = sides["specs"]
    msg = side.by_name[name]
    check_roundtrip(side, msg, data.draw(side.draw.message(msg)))


@pytest.mark.parametrize("name", _names(SPECS))
@settings(SWEEP, max_examples=_examples(6))
@given(data=st.data())
def test_specs_type_round_trips_exactly(sides: dict[str, Side], name: str, data: st.DataObject) -> None:
    side = sides["specs"]
    msg = side.by_name[name]
    check_roundtrip(side, msg, data.draw(side.exact.message(msg)), exact=True)


@pytest.mark.parametrize("name", _names(BUNDLED))
@settings(SWEEP, max_examples=_examples(60))
@given(data=st.data())
def test_bundled_type_matches_pydronecan(sides: dict[str, Side], name: str, data: st.DataObject) -> None:
    side = sides["bundled"]
    msg = side.by_name[name]
    check_roundtrip(side, msg, data.draw(side.draw.message(msg)))


@settings(SWEEP, max_examples=_examples(250))
@given(data=st.data())
def test_battery_info_matches_pydronecan(sides: dict[str, Side], data: st.DataObject) -> None:
    side = sides["bundled"]
    msg = side.by_name["dronecan.uavcan.equipment.power.BatteryInfo"]
    check_roundtrip(side, msg, data.draw(side.draw.message(msg)))


def _branches(root: Path) -> list[tuple[str, str]]:
    return [
        (m.qualified_name, f.name)
        for m in dsdl.parse_dir(root).messages
        if m.dronecan is not None and m.dronecan.union
        for f in m.fields
    ]


@pytest.mark.parametrize(("name", "branch"), _branches(SPECS))
@settings(SWEEP, max_examples=_examples(6))
@given(data=st.data())
def test_every_union_branch_matches_pydronecan(
    sides: dict[str, Side], name: str, branch: str, data: st.DataObject
) -> None:
    """Constructed by one field (``Value(integer_value=42)``), a union encodes that branch as pydronecan does."""
    side = sides["specs"]
    msg = side.by_name[name]
    exact = data.draw(st.booleans())
    value = data.draw((side.exact if exact else side.draw).field(msg.field(branch).type))
    check_roundtrip(side, msg, {"_branch": branch, branch: value}, exact=exact)


def _resolve(package: str, qualified: str) -> Any:
    """The object a qualified name (as ``battgen list`` prints it) names in the generated package."""
    parts = qualified.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join([package, *parts[:cut]]))
        except ModuleNotFoundError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)
        return obj
    raise AssertionError(qualified)


def test_every_listed_name_is_importable_as_written(sides: dict[str, Side]) -> None:
    """DSDL names are kept exactly (CBAT, PUSHCAN), and a service's halves are GetSet.Request / .Response."""
    side = sides["specs"]
    for msg in side.schema.messages:
        assert _resolve(side.package, msg.qualified_name) is side.cls(msg), msg.qualified_name
    assert side.cls(side.by_name["dronecan.cuav.equipment.power.CBAT"]).__name__ == "CBAT"


def test_ids_signatures_and_transfer_crc(sides: dict[str, Side]) -> None:
    for side in sides.values():
        for msg in side.schema.messages:
            cls = side.cls(msg)
            ref = side.ref_type(msg)
            assert cls.DATA_TYPE_ID == ref.default_dtid
            assert cls.DATA_TYPE_SIGNATURE == ref.get_data_type_signature()
    side = sides["bundled"]
    cls = side.cls(side.by_name["dronecan.uavcan.equipment.power.BatteryInfo"])
    runtime = importlib.import_module("dc_bundled._dronecan")
    # pydronecan defaults every field to zero; ours default to the sentinels (NaN, 127), so set them
    unknown_as_zero = dict.fromkeys(
        (
            "temperature",
            "average_power_10sec",
            "remaining_capacity_wh",
            "full_charge_capacity_wh",
            "hours_to_full_charge",
        ),
        0.0,
    )
    obj = cls(
        voltage=16.8,
        current=-3.5,
        model_name=b"battgen test pack 4S",
        model_instance_id=7,
        state_of_health_pct=0,
        state_of_charge_pct=0,  # its default is STATE_OF_CHARGE_UNKNOWN (127) since dronecan/DSDL's 2026 change
        **unknown_as_zero,
    )
    payload = obj.encode()
    # pydronecan's own transfer: a multi-frame transfer starts with the CRC, seeded by the signature
    ref = dronecan.uavcan.equipment.power.BatteryInfo(
        voltage=16.8, current=-3.5, model_name="battgen test pack 4S", model_instance_id=7
    )
    transfer = transport.Transfer(payload=ref, source_node_id=10, transfer_id=3)
    assert bytes(transfer.payload) == payload
    first = bytes(transfer.to_frames()[0].bytes)
    assert first[0] | (first[1] << 8) == runtime.transfer_crc(cls.DATA_TYPE_SIGNATURE, payload)
    base = pydsdl.crc16_from_bytes(cls.DATA_TYPE_SIGNATURE.to_bytes(8, "little"))
    assert runtime.transfer_crc(cls.DATA_TYPE_SIGNATURE, payload) == pydsdl.crc16_from_bytes(payload, initial=base)
