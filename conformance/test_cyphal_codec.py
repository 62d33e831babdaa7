"""The generated Cyphal codecs against pydsdl's own ``serialize`` / ``deserialize``.

Hypothesis draws values in pydsdl's form from pydsdl's own reading of each type (so the strategy follows the
reference, not our IR); each value is built into our generated class and must serialize to pydsdl's bytes,
and those bytes (and random bytes) must read back as pydsdl reads them. Covered: every bundled battery and
physics type (schemas/cyphal/, the committed package), every type of the regulated set
(../shared/corpus/cyphal/, generated into a temporary package), the saturated and truncated casts of every
width on values out of range, and the delimiter header of nested and top-level delimited types.
"""

from __future__ import annotations

import importlib
import math
import sys
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import pydsdl
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shared_data import shared

from codegen.backends.python import naming
from codegen.backends.python.writer import generate
from codegen.frontends import cyphal
from codegen.frontends.cyphal.build import type_name
from codegen.ir import Schema

ROOT = Path(__file__).resolve().parents[1]
OURS = ROOT / "schemas" / "cyphal"
CORPUS = shared("corpus", "cyphal")
needs_corpus = pytest.mark.skipif(not (CORPUS / "reg").is_dir(), reason="the Cyphal corpus is not present")
SWEEP = settings(max_examples=25, derandomize=True, database=None, deadline=None)
_ARRAY_DRAW = 6  # elements drawn at most for a variable-length array (its prefix is what matters)


def _read(root: Path) -> list[pydsdl.CompositeType]:
    spaces = sorted(p for p in root.iterdir() if p.is_dir())
    return [t for s in spaces for t in pydsdl.read_namespace(s, [o for o in spaces if o != s])]


def _halves(t: pydsdl.CompositeType) -> list[tuple[str, pydsdl.CompositeType]]:
    if isinstance(t, pydsdl.ServiceType):
        base = type_name(t)
        return [(base + ".Request", t.request_type), (base + ".Response", t.response_type)]
    return [(type_name(t), t)]


# ---- values in pydsdl's form ---------------------------------------------------------------------------


def values(t: pydsdl.SerializableType) -> st.SearchStrategy[Any]:
    """Every value of ``t`` pydsdl serializes (a variable-length array drawn up to a few elements)."""
    if isinstance(t, pydsdl.DelimitedType):
        return values(t.inner_type)
    if isinstance(t, pydsdl.BooleanType):
        return st.booleans()
    if isinstance(t, pydsdl.FloatType):
        return st.floats(width=t.bit_length)  # NaN and the infinities included
    if isinstance(t, pydsdl.IntegerType):
        r = t.inclusive_value_range
        return st.integers(int(r.min), int(r.max))
    if isinstance(t, pydsdl.ArrayType):
        element = t.element_type
        top = t.capacity if isinstance(t, pydsdl.FixedLengthArrayType) else min(t.capacity, _ARRAY_DRAW)
        low = t.capacity if isinstance(t, pydsdl.FixedLengthArrayType) else 0
        if isinstance(element, pydsdl.UTF8Type):
            return st.text(max_size=top).filter(lambda s: len(s.encode()) <= t.capacity)
        if isinstance(element, pydsdl.ByteType):
            return st.binary(min_size=low, max_size=top)
        return st.lists(values(element), min_size=low, max_size=top)
    if isinstance(t, pydsdl.UnionType):
        return st.one_of([st.fixed_dictionaries({f.name: values(f.data_type)}) for f in t.fields])
    assert isinstance(t, pydsdl.StructureType), t
    return st.fixed_dictionaries({f.name: values(f.data_type) for f in t.fields_except_padding})


def plain(v: Any) -> Any:
    """pydsdl's form -> our classes' plain data (``from_dict`` / ``to_dict``): text and bytes as lists of ints."""
    if isinstance(v, str):
        return list(v.encode())
    if isinstance(v, bytes | bytearray):
        return list(v)
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items() if k != "union_field"}
    if isinstance(v, list | tuple):
        return [plain(x) for x in v]
    return v


def same(v: Any) -> Any:
    """Comparable plain data: NaN equal to NaN."""
    v = plain(v)
    if isinstance(v, float) and math.isnan(v):
        return "NaN"
    if isinstance(v, dict):
        return {k: same(x) for k, x in v.items()}
    if isinstance(v, list):
        return [same(x) for x in v]
    return v


def check_value(cls: Any, t: pydsdl.CompositeType, value: Any) -> None:
    ours = cls.from_dict(plain(value))
    data = pydsdl.serialize(t, value)
    assert ours.encode() == data
    assert same(cls.decode(data).to_dict()) == same(pydsdl.deserialize(t, data))
    if isinstance(t, pydsdl.DelimitedType):
        headed = pydsdl.serialize(t, value, with_delimiter_header=True)
        assert ours.encode(with_delimiter_header=True) == headed
        assert cls.decode(headed, with_delimiter_header=True).encode() == data


def check_bytes(cls: Any, t: pydsdl.CompositeType, data: bytes) -> None:
    """Any bytes read as pydsdl reads them, or refused where pydsdl refuses them."""
    try:
        expected = pydsdl.deserialize(t, data)
    except UnicodeDecodeError:  # pydsdl checks utf8 text; our classes hold it as bytes
        assert cls.decode(data).encode() is not None
        return
    except pydsdl.SerDesError:
        with pytest.raises(ValueError, match=r"\S"):
            cls.decode(data)
        return
    got = cls.decode(data)
    assert same(got.to_dict()) == same(expected)


# ---- the committed package: the bundled battery and physics types ----------------------------------------


@cache
def _bundled() -> dict[str, tuple[Any, pydsdl.CompositeType]]:
    schema = cyphal.parse_dir(OURS)
    out = {}
    for t in _read(OURS):
        for name, part in _halves(t):
            msg = schema.message(name)
            module = importlib.import_module("generated." + naming.module_path(msg))
            out[name] = (getattr(module, naming.class_name(msg)), part)
    return out


BUNDLED = sorted(_bundled())


def test_every_bundled_type_has_a_codec() -> None:
    assert len(BUNDLED) == 19
    for cls, t in _bundled().values():
        assert cls.EXTENT_BYTES * 8 == t.extent
        assert cls.SEALED is not isinstance(t, pydsdl.DelimitedType)


@pytest.mark.parametrize("name", BUNDLED)
@SWEEP
@given(data=st.data())
def test_bundled_values_as_pydsdl(name: str, data: st.DataObject) -> None:
    cls, t = _bundled()[name]
    check_value(cls, t, data.draw(values(t)))


@pytest.mark.parametrize("name", BUNDLED)
@SWEEP
@given(raw=st.binary(max_size=80))
def test_bundled_bytes_as_pydsdl(name: str, raw: bytes) -> None:
    cls, t = _bundled()[name]
    check_bytes(cls, t, raw)


def test_status_known_bytes() -> None:
    """A hand-checked Status.0.2: readiness and health, two temperatures, the charge, an error, two cells."""
    from generated.cyphal.reg.udral.service.battery import Status_0_2

    status = Status_0_2.from_dict(
        {
            "heartbeat": {"readiness": {"value": 3}, "health": {"value": 2}},
            "temperature_min_max": [{"kelvin": 300.0}, {"kelvin": 310.5}],
            "available_charge": {"coulomb": 1.5},
            "error": {"value": 62},
            "cell_voltages": [3.5, 4.0],
        }
    )
    data = status.encode()
    # readiness (2 bits) and health (2 bits) share byte 0 after Heartbeat's own layout; float16 3.5 = 0x4300
    assert data[-4:] == bytes.fromhex("00430044")
    assert data[-5] == 2  # two cells: the uint8 length prefix
    assert Status_0_2.decode(data) == status


# ---- casts: saturated and truncated (Cyphal truncates unsigned types only), values out of range ---------

CASTS = """\
saturated uint3 u3
truncated uint3 t3
saturated int5 i5
int64 i64
saturated uint64 u64
truncated uint64 tu64
saturated float16 f16
truncated float16 tf16
saturated float32 f32
truncated float32 tf32
float64 f64
bool flag
void3
truncated uint9[<=3] nine
@sealed
"""


@pytest.fixture(scope="module")
def casts(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Any, pydsdl.CompositeType]]:
    base = tmp_path_factory.mktemp("cy_casts")
    (base / "dsdl" / "casts").mkdir(parents=True)
    (base / "dsdl" / "casts" / "Casts.1.0.dsdl").write_text(CASTS)
    generate(cyphal.parse_dir(base / "dsdl"), base / "out" / "cy_casts")
    sys.path.insert(0, str(base / "out"))
    try:
        module = importlib.import_module("cy_casts.cyphal.casts")
        yield module.Casts_1_0, pydsdl.read_namespace(base / "dsdl" / "casts")[0]
    finally:
        sys.path.remove(str(base / "out"))
        for name in [n for n in sys.modules if n.split(".")[0] == "cy_casts"]:
            del sys.modules[name]


_BIG = st.integers(-(1 << 70), 1 << 70)
_ANY_FLOAT = st.one_of(st.floats(), st.floats(-70000, 70000), st.floats(-4e38, 4e38))


@settings(SWEEP, max_examples=200)
@given(
    ints=st.lists(_BIG, min_size=6, max_size=6),
    floats=st.lists(_ANY_FLOAT, min_size=5, max_size=5),
    nine=st.lists(_BIG, max_size=3),
)
def test_casts_as_pydsdl(
    casts: tuple[Any, pydsdl.CompositeType], ints: list[int], floats: list[float], nine: list[int]
) -> None:
    cls, t = casts
    names = ["u3", "t3", "i5", "i64", "u64", "tu64"]
    value: dict[str, Any] = dict(zip(names, ints, strict=True))
    value.update(zip(["f16", "tf16", "f32", "tf32", "f64"], floats, strict=True))
    value.update(flag=True, nine=nine)
    ours = cls()
    for key, item in value.items():
        setattr(ours, key, item)
    assert ours.encode() == pydsdl.serialize(t, value)


def test_array_too_long_is_refused(casts: tuple[Any, pydsdl.CompositeType]) -> None:
    cls, _ = casts
    ours = cls()
    ours.nine = [1, 2, 3, 4]
    with pytest.raises(ValueError, match=r"at most 3 elements, got 4"):
        ours.encode()


# ---- the regulated set: every type the frontend reads ---------------------------------------------------


@cache
def _corpus_schema() -> Schema:
    return cyphal.parse_dir(CORPUS)


@cache
def _corpus_types() -> dict[str, pydsdl.CompositeType]:
    return {name: part for t in _read(CORPUS) for name, part in _halves(t)}


@pytest.fixture(scope="module")
def corpus_package(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    base = tmp_path_factory.mktemp("cy_corpus")
    generate(_corpus_schema(), base / "cy_corpus")
    sys.path.insert(0, str(base))
    try:
        yield "cy_corpus"
    finally:
        sys.path.remove(str(base))
        for name in [n for n in sys.modules if n.split(".")[0] == "cy_corpus"]:
            del sys.modules[name]


def _corpus_class(package: str, name: str) -> Any:
    msg = _corpus_schema().message(name)
    return getattr(importlib.import_module(f"{package}.{naming.module_path(msg)}"), naming.class_name(msg))


CORPUS_NAMES = sorted(_corpus_types()) if (CORPUS / "reg").is_dir() else []


@needs_corpus
def test_corpus_has_every_type() -> None:
    assert len(CORPUS_NAMES) > 150
    assert {m.qualified_name for m in _corpus_schema().messages} == set(CORPUS_NAMES)


CORPUS_SWEEP = settings(
    SWEEP,
    max_examples=5,
    suppress_health_check=[HealthCheck.large_base_example, HealthCheck.filter_too_much, HealthCheck.too_slow],
)


@needs_corpus
@pytest.mark.parametrize("name", CORPUS_NAMES)
@CORPUS_SWEEP
@given(data=st.data())
def test_corpus_values_as_pydsdl(corpus_package: str, name: str, data: st.DataObject) -> None:
    t = _corpus_types()[name]
    check_value(_corpus_class(corpus_package, name), t, data.draw(values(t)))


@needs_corpus
@pytest.mark.parametrize("name", CORPUS_NAMES)
@CORPUS_SWEEP
@given(raw=st.binary(max_size=40))
def test_corpus_bytes_as_pydsdl(corpus_package: str, name: str, raw: bytes) -> None:
    check_bytes(_corpus_class(corpus_package, name), _corpus_types()[name], raw)
