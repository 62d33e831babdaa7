"""The generated uORB codec: PX4's C struct layout, round trips, batch columns and error paths."""

from __future__ import annotations

import dataclasses
import math
import struct
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from samples import NESTED

from codegen.frontends import uorb
from generated import _uorb
from generated.uorb import BatteryStatus, BatteryStatusV0

# A nested schema exercising every kind of slot: nested structs and arrays of them, char[N],
# uint8[N] (bytes), one char, bools, 8/16/32/64-bit integers, float32/64, inner padding.

_INTS = {"int8": 8, "int16": 16, "int32": 32, "int64": 64}


def scalar(type_text: str) -> st.SearchStrategy[Any]:
    if type_text == "bool":
        return st.booleans()
    if type_text == "float32":
        return st.floats(width=32)
    if type_text == "float64":
        return st.floats()
    if type_text == "char":
        return st.characters(max_codepoint=255, exclude_characters="\0") | st.just("")
    if type_text.startswith("uint"):
        return st.integers(0, (1 << int(type_text[4:])) - 1)
    bits = _INTS[type_text]
    return st.integers(-(1 << (bits - 1)), (1 << (bits - 1)) - 1)


def instances(cls: type[Any]) -> st.SearchStrategy[Any]:
    """Random instances of a generated uORB class, from its field metadata."""
    proto = cls()
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for f in dataclasses.fields(cls):
        text = f.metadata["type"]
        default = getattr(proto, f.name)
        if text.startswith("char["):
            alphabet = st.characters(exclude_characters="\0", max_codepoint=0x7FF)
            fields[f.name] = st.text(alphabet, max_size=int(text[5:-1]) // 2)
        elif isinstance(default, bytes):
            fields[f.name] = st.binary(min_size=len(default), max_size=len(default))
        elif isinstance(default, list):
            n = len(default)
            inner = instances(type(default[0])) if dataclasses.is_dataclass(default[0]) else scalar(text.split("[")[0])
            fields[f.name] = st.lists(inner, min_size=n, max_size=n)
        elif dataclasses.is_dataclass(default):
            fields[f.name] = instances(type(default))
        else:
            fields[f.name] = scalar(text)
    return st.builds(cls, **fields)


def same(a: Any, b: Any) -> bool:
    """Equality of plain data where NaN equals NaN."""
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or a == b
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


@pytest.fixture
def nested(import_generated: Any, tmp_path: Path) -> ModuleType:
    src = tmp_path / "msg"
    src.mkdir()
    for name, text in NESTED.items():
        (src / name).write_text(text, encoding="utf-8")
    module: ModuleType = import_generated(uorb.parse_dir(src), "uorb")
    return module


def test_class_attributes_follow_the_ir() -> None:
    schema = uorb.parse_dir(ROOT / "schemas" / "uorb")
    for cls, name in ((BatteryStatus, "uorb.BatteryStatus"), (BatteryStatusV0, "uorb.BatteryStatusV0")):
        info = schema.message(name).uorb
        assert info is not None
        assert cls.UORB_SIZE == info.struct_size == struct.calcsize(cls.UORB_FORMAT) == len(cls().encode())
        assert cls.UORB_TOPICS == info.topics and cls.MESSAGE_VERSION == info.message_version
        assert cls.UORB_SIZE_NO_PADDING == cls.UORB_SIZE - (
            info.layout[-1].size if info.layout[-1].field is None else 0
        )
    assert BatteryStatus.UORB_FORMAT == "<Q33f9H?4B2?B2x" and BatteryStatusV0.UORB_FORMAT == "<Q33f10H?4B2?B"


def test_encode_puts_each_field_at_its_px4_offset() -> None:
    schema = uorb.parse_dir(ROOT / "schemas" / "uorb")
    info = schema.message("uorb.BatteryStatus").uorb
    assert info is not None
    msg = BatteryStatus(timestamp=0x0102030405060708, voltage_v=15.5, capacity=5000, warning=3, is_required=True)
    msg.voltage_cell_v = [float(i) for i in range(14)]
    data = msg.encode()
    at = {s.name: s.offset for s in info.layout}
    assert struct.unpack_from("<Q", data, at["timestamp"])[0] == 0x0102030405060708
    assert struct.unpack_from("<f", data, at["voltage_v"])[0] == 15.5
    assert struct.unpack_from("<14f", data, at["voltage_cell_v"]) == tuple(float(i) for i in range(14))
    assert struct.unpack_from("<H", data, at["capacity"])[0] == 5000
    assert data[at["warning"]] == 3 and data[at["is_required"]] == 1
    assert data[at["_padding0"] :] == b"\0\0"


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.one_of(instances(BatteryStatus), instances(BatteryStatusV0)))
def test_round_trip(msg: Any) -> None:
    cls = type(msg)
    data = msg.encode()
    assert len(data) == cls.UORB_SIZE
    back = cls.decode(data)
    assert same(back.to_dict(), msg.to_dict())
    assert same(cls.decode(data[: cls.UORB_SIZE_NO_PADDING]).to_dict(), msg.to_dict())  # a ULog record
    assert back.encode() == data


def test_nested_layout_and_round_trip(nested: ModuleType) -> None:
    inner_cls, outer_cls = nested.Inner, nested.Outer
    # Inner: u64, f32, i16[3] = 18 bytes, u8, char[5] -> 24, already a multiple of 8
    assert inner_cls.UORB_SIZE == 24 and inner_cls.UORB_FORMAT == "<Qf3hB5s"
    assert outer_cls.UORB_SIZE == struct.calcsize(outer_cls.UORB_FORMAT)
    # nested structs come last, each after padding to 8: their codes are inlined
    assert outer_cls.UORB_FORMAT.endswith("Qf3hB5sQf3hB5sQf3hB5s")

    @settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
    @given(instances(outer_cls))
    def check(msg: Any) -> None:
        data = msg.encode()
        back = outer_cls.decode(data)
        assert same(back.to_dict(), msg.to_dict()) and back.encode() == data
        assert isinstance(back.one, inner_cls) and all(isinstance(x, inner_cls) for x in back.many)

    check()


def test_nested_padding_is_zero_and_format_matches_the_ulog_text(nested: ModuleType) -> None:
    outer = nested.Outer(raw=b"\xff" * 4, ok=True, c="z")
    fmt = nested.Outer.ulog_format()
    text = fmt.text()
    assert text.startswith("outer:uint64_t timestamp;double d;int64_t i64;uint32_t u32;uint8_t[4] raw;bool ok;char c;")
    assert "int8_t s8;uint8_t[5] _padding0;inner one;inner[2] many;" in text  # 35 bytes, padded to 40
    offset = struct.calcsize("<QdqI4s?cb")  # the fields before the padding
    assert offset == 35 and outer.encode()[offset:40] == bytes(5)


def test_decode_rejects_a_wrong_length() -> None:
    with pytest.raises(_uorb.DecodeError, match=r"BatteryStatus: expected 168 bytes \(or 166 .*\), got 167"):
        BatteryStatus.decode(bytes(167))
    with pytest.raises(_uorb.DecodeError, match=r"BatteryStatusV0: expected 168 bytes, got 169"):
        BatteryStatusV0.decode(bytes(169))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"cell_count": 256}, r"BatteryStatus\.cell_count: .*0 <= number <= 255.*value 256"),
        ({"capacity": -1}, r"BatteryStatus\.capacity: .*value -1"),
        ({"voltage_v": 1e39}, r"BatteryStatus\.voltage_v: .*too large.*value 1e\+39"),
        ({"voltage_v": "12"}, r"BatteryStatus\.voltage_v: .*value '12'"),
        ({"voltage_cell_v": [0.0] * 13}, r"BatteryStatus\.voltage_cell_v: expected a list of 14 items"),
        ({"timestamp": None}, r"BatteryStatus\.timestamp: .*value None"),
    ],
)
def test_encode_names_the_bad_field(change: dict[str, Any], message: str) -> None:
    with pytest.raises(_uorb.EncodeError, match=message):
        dataclasses.replace(BatteryStatus(), **change).encode()


def test_encode_names_nested_fields(nested: ModuleType) -> None:
    outer = nested.Outer()
    outer.one.tag = "toolong"
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.one\.tag: 7 bytes of UTF-8 exceed capacity 5"):
        outer.encode()
    outer = nested.Outer()
    outer.many[1].flag = 300
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.many\[1\]\.flag: .*value 300"):
        outer.encode()
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.many: expected a list of 2 Inner"):
        nested.Outer(many=[nested.Inner()]).encode()
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.one: expected a Inner, got 3"):
        nested.Outer(one=3).encode()
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.raw: expected 4 bytes, got b'abc'"):
        nested.Outer(raw=b"abc").encode()
    with pytest.raises(nested._uorb.EncodeError, match=r"Outer\.c: expected one Latin-1 character, got 'ab'"):
        nested.Outer(c="ab").encode()


def test_decode_batch_matches_per_record_decode() -> None:
    msgs = [BatteryStatus(timestamp=i, voltage_v=i / 4, cell_count=i % 7, connected=bool(i % 2)) for i in range(50)]
    for m in msgs:
        m.voltage_cell_v[3] = m.voltage_v
    full = b"".join(m.encode() for m in msgs)
    short = b"".join(m.encode()[: BatteryStatus.UORB_SIZE_NO_PADDING] for m in msgs)
    lists = BatteryStatus.decode_batch(full, use_numpy=False)
    assert lists["timestamp"] == list(range(50)) and lists["voltage_cell_v[3]"] == [m.voltage_v for m in msgs]
    assert lists["connected"] == [m.connected for m in msgs] and "_padding0" not in lists
    arrays = BatteryStatus.decode_batch(short, stride=BatteryStatus.UORB_SIZE_NO_PADDING, use_numpy=True)
    assert list(arrays) == list(lists)
    for name, column in lists.items():
        assert same([x.item() for x in arrays[name]], column), name
    views = BatteryStatus.decode_batch(full, use_numpy=True, copy=False)
    assert views["cell_count"].tolist() == lists["cell_count"]


def test_decode_batch_of_nested_records(nested: ModuleType) -> None:
    a, b = nested.Outer(timestamp=1), nested.Outer(timestamp=2)
    a.many[1].v = [1, -2, 3]
    b.one.tag = "abc"
    cols = nested.Outer.decode_batch(a.encode() + b.encode(), use_numpy=False)
    assert cols["many[1].v[1]"] == [-2, 0] and cols["one.tag"] == [b"\0" * 5, b"abc\0\0"]
    arrays = nested.Outer.decode_batch(a.encode() + b.encode(), use_numpy=True)
    assert arrays["many[1].v[1]"].tolist() == [-2, 0] and arrays["one.tag"].tolist() == [b"", b"abc"]
    assert cols["raw[0]"] == [0, 0] and len(cols) == len(arrays)


def test_decode_batch_rejects_bad_buffers() -> None:
    empty = BatteryStatus.decode_batch(b"", use_numpy=False)
    assert empty["timestamp"] == [] and len(BatteryStatus.decode_batch(b"")["timestamp"]) == 0
    with pytest.raises(_uorb.DecodeError, match="170 bytes are not a whole number of 168-byte records"):
        BatteryStatus.decode_batch(bytes(170), use_numpy=False)
    with pytest.raises(_uorb.DecodeError, match="records of 100 bytes are shorter than the 166"):
        BatteryStatus.decode_batch(bytes(200), stride=100)
    with pytest.raises(_uorb.DecodeError, match="expected a positive record size, got 0"):
        BatteryStatus.decode_batch(bytes(200), stride=0)


def test_a_field_named_like_a_codec_method_is_renamed(tmp_path: Path, import_generated: Any) -> None:
    (tmp_path / "Clash.msg").write_text("uint64 timestamp\nuint8 decode_batch\n", encoding="utf-8")
    cls = import_generated(uorb.parse_dir(tmp_path), "uorb").Clash
    value = cls(timestamp=5, decode_batch_=9)
    assert cls.decode(value.encode()) == value and value.to_dict() == {"timestamp": 5, "decode_batch": 9}
    assert callable(cls.decode_batch)


def test_batch_falls_back_to_struct_without_numpy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_uorb, "_NUMPY", [None])  # as if numpy were not installed
    data = BatteryStatus(timestamp=5).encode() * 2
    assert BatteryStatus.decode_batch(data)["timestamp"] == [5, 5]
    with pytest.raises(ImportError, match="use_numpy=True needs numpy"):
        BatteryStatus.decode_batch(data, use_numpy=True)
