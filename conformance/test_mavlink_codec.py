"""Our generated MAVLink codec against pymavlink: payload and frame bytes, and each side parsing the other.

BATTERY_STATUS comes from the committed package (schemas/mavlink/battery.xml); the sweep over
every message of pymavlink's common.xml generates a package of its own into a temporary folder.
"""

from __future__ import annotations

import importlib
import math
import struct
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pymavlink
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v10 import common as v10
from pymavlink.dialects.v20 import common as v20

from codegen.backends.python.writer import generate
from codegen.frontends import mavlink as frontend
from codegen.ir import ArrayType, Field, Message, PrimitiveKind, PrimitiveType, StringType
from generated import _mavlink as runtime
from generated.mavlink import BatteryStatus

COMMON_XML = Path(pymavlink.__file__).parent / "dialects" / "v20" / "common.xml"
ROOT = Path(__file__).resolve().parent.parent
FAST = settings(max_examples=60, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))


def _int(bits: int, signed: bool) -> st.SearchStrategy[int]:
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return st.one_of(st.sampled_from([lo, hi, 0, -1 if signed else hi]), st.integers(lo, hi))


def _float(bits: int) -> st.SearchStrategy[float]:
    # any value the wire type holds exactly (NaN and infinities included), so bytes compare
    return st.floats(width=64 if bits == 64 else 32, allow_nan=True, allow_infinity=True)


def _scalar(t: PrimitiveType) -> st.SearchStrategy[Any]:
    if t.kind is PrimitiveKind.FLOAT:
        return _float(t.bits)
    return _int(t.bits, t.kind is PrimitiveKind.INT)


def _ascii(size: int) -> st.SearchStrategy[str]:
    return st.text(st.characters(min_codepoint=1, max_codepoint=127), max_size=size)


def _field_values(f: Field) -> st.SearchStrategy[Any]:
    t = f.type
    if isinstance(t, StringType):
        return _ascii(t.capacity or 1)
    if isinstance(t, PrimitiveType) and t.kind is PrimitiveKind.CHAR:
        return _ascii(1)
    if isinstance(t, ArrayType) and isinstance(t.element, PrimitiveType) and t.capacity:
        if t.element.kind is PrimitiveKind.UINT and t.element.bits == 8:
            return st.binary(min_size=t.capacity, max_size=t.capacity)
        return st.lists(_scalar(t.element), min_size=t.capacity, max_size=t.capacity)
    assert isinstance(t, PrimitiveType)
    return _scalar(t)


def _instances(msg: Message, cls: Any) -> st.SearchStrategy[Any]:
    """Random instances: every field (extensions too) over its full range; some left at their sentinels."""
    strategies = {f.name: st.one_of(st.none(), _field_values(f)) if f.invalid else _field_values(f) for f in msg.fields}

    def build(values: dict[str, Any]) -> Any:
        return cls.from_dict({k: v for k, v in values.items() if v is not None})

    return st.fixed_dictionaries(strategies).map(build)


def _pymavlink_args(obj: Any, pm_cls: Any) -> list[Any]:
    """Our instance's values as pymavlink's constructor takes them (text and char as bytes)."""
    args = []
    for name, ftype in zip(pm_cls.fieldnames, pm_cls.fieldtypes, strict=True):
        value = obj.to_dict()[name]
        if ftype == "char":
            value = value.encode("utf-8", "surrogateescape")
        elif ftype == "uint8_t" and isinstance(value, list):
            value = bytes(value)
        args.append(value)
    return args


def _mav(cls: Any = v20.MAVLink, seq: int = 0, sysid: int = 1, compid: int = 1) -> Any:
    mav = cls(None, srcSystem=sysid, srcComponent=compid)
    mav.seq = seq
    return mav


def _same(ours: Any, theirs: Any) -> bool:
    """Equal field values, NaN equal to NaN; pymavlink's uint8 arrays may be lists or bytes."""
    if isinstance(ours, float) and isinstance(theirs, float):
        return (math.isnan(ours) and math.isnan(theirs)) or ours == theirs
    if isinstance(ours, list | tuple | bytes) and isinstance(theirs, list | tuple | bytes):
        return len(ours) == len(theirs) and all(_same(a, b) for a, b in zip(ours, theirs, strict=True))
    return bool(ours == theirs)


def _assert_values(ours: Any, theirs: Any, names: list[str]) -> None:
    for name in names:
        mine = ours.to_dict()[name]
        other = getattr(theirs, name)
        if isinstance(other, bytes) and isinstance(mine, str):
            other = other.decode("ascii")
        assert _same(mine, other), (name, mine, other)


BATTERY = frontend.parse_file(ROOT / "schemas" / "mavlink" / "battery.xml").message("mavlink.BATTERY_STATUS")
PM_BATTERY = v20.MAVLink_battery_status_message


# --------------------------------------------------------------------------------------------
# BATTERY_STATUS, many examples


@FAST
@given(_instances(BATTERY, BatteryStatus), st.integers(0, 255), st.integers(0, 255), st.integers(0, 255))
def test_battery_status_bytes_equal_pymavlink(obj: BatteryStatus, seq: int, sysid: int, compid: int) -> None:
    theirs = PM_BATTERY(*_pymavlink_args(obj, PM_BATTERY))
    frame = theirs.pack(_mav(seq=seq, sysid=sysid, compid=compid))
    assert obj.encode() == bytes(theirs.get_payload())
    assert obj.encode_frame(seq=seq, sysid=sysid, compid=compid) == frame
    # both directions of parsing
    parsed = _mav().parse_buffer(obj.encode_frame(seq=seq, sysid=sysid, compid=compid))
    assert parsed is not None and len(parsed) == 1
    _assert_values(obj, parsed[0], list(PM_BATTERY.fieldnames))
    assert (parsed[0].get_seq(), parsed[0].get_srcSystem(), parsed[0].get_srcComponent()) == (seq, sysid, compid)
    back = runtime.decode_message(frame)
    _assert_values(back, theirs, list(PM_BATTERY.fieldnames))
    head = runtime.parse_frame(frame)
    assert (head.version, head.msgid, head.seq, head.sysid, head.compid) == (2, 147, seq, sysid, compid)
    assert BatteryStatus.decode(obj.encode()).encode(truncate=False) == obj.encode(truncate=False)


@FAST
@given(_instances(BATTERY, BatteryStatus), st.integers(0, 255))
def test_battery_status_mavlink1_frames(obj: BatteryStatus, seq: int) -> None:
    # pymavlink's v1.0 dialect knows the base fields only, as a MAVLink 1 receiver does
    base = [n for n in PM_BATTERY.fieldnames if n in v10.MAVLink_battery_status_message.fieldnames]
    theirs = v10.MAVLink_battery_status_message(*_pymavlink_args(obj, v10.MAVLink_battery_status_message))
    assert obj.encode_frame(seq=seq, mavlink1=True) == theirs.pack(_mav(v10.MAVLink, seq=seq))
    parsed = _mav().parse_buffer(obj.encode_frame(seq=seq, mavlink1=True))
    assert parsed is not None and len(parsed) == 1
    _assert_values(obj, parsed[0], base)
    for name in set(PM_BATTERY.fieldnames) - set(base):  # extensions arrive zero-filled on both sides
        value = getattr(BatteryStatus.decode_frame(obj.encode_frame(mavlink1=True)), name)
        assert value == getattr(parsed[0], name) and not any(value if isinstance(value, list) else [value])


def test_signed_frames_from_pymavlink_parse() -> None:
    mav = _mav(seq=5, sysid=3, compid=4)
    mav.signing.secret_key = bytes(range(32))
    mav.signing.link_id = 7
    mav.signing.sign_outgoing = True
    mav.signing.timestamp = 123456789
    obj = BatteryStatus(id=2, voltages=[3700] * 10, fault_bitmask=0x80)
    frame = PM_BATTERY(*_pymavlink_args(obj, PM_BATTERY)).pack(mav)
    head = runtime.parse_frame(frame)
    assert head.signed and head.incompat_flags == 1 and head.link_id == 7 and head.timestamp == 123456789
    assert head.signature == frame[-13:]
    assert runtime.decode_message(frame) == obj == BatteryStatus.decode_frame(frame)
    # and the frame we build around that signature is the same frame
    ours = obj.encode_frame(seq=5, sysid=3, compid=4, signature=head.signature)
    assert ours == frame


def test_stream_parser_reads_pymavlink_stream_with_garbage() -> None:
    mav = _mav()
    objs = [BatteryStatus(id=i, current_consumed=i * 1000, voltages=[4000 + i] * 10) for i in range(20)]
    frames = [PM_BATTERY(*_pymavlink_args(o, PM_BATTERY)).pack(mav) for o in objs]
    corrupt = bytearray(frames[3])
    corrupt[12] ^= 0xFF
    stream = b"\x00\xfd\x01garbage\xfe" + b"".join(frames[:3]) + bytes(corrupt) + b"".join(frames[3:])
    parser = runtime.StreamParser()
    got = []
    for i in range(0, len(stream), 17):  # odd-sized pieces split frames anywhere
        got += parser.feed_messages(stream[i : i + 17])
    assert got == objs
    assert parser.frames == 20 and parser.bad_crc >= 1 and parser.skipped_bytes > 0
    assert parser.last_error is not None and "bad CRC" in parser.last_error


# --------------------------------------------------------------------------------------------
# every message of common.xml


@pytest.fixture(scope="module")
def common_pkg(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ModuleType, dict[str, Message]]]:
    schema = frontend.parse_file(COMMON_XML)
    root = tmp_path_factory.mktemp("mav")
    generate(schema, root / "mavpkg")
    sys.path.insert(0, str(root))
    try:
        importlib.invalidate_caches()
        module = importlib.import_module("mavpkg.mavlink")
        yield module, {m.name: m for m in schema.messages}
    finally:
        sys.path.remove(str(root))
        for name in [m for m in sys.modules if m == "mavpkg" or m.startswith("mavpkg.")]:
            del sys.modules[name]


def _pm_class(name: str) -> Any:
    return v20.mavlink_map[getattr(v20, f"MAVLINK_MSG_ID_{name}")]


def test_common_xml_every_message_matches_pymavlink(common_pkg: tuple[ModuleType, dict[str, Message]]) -> None:
    _, messages = common_pkg
    from mavpkg import _mavlink as rt  # type: ignore[import-not-found]

    assert len(messages) > 200
    checked = 0
    stats = {"v1.0 dialect": 0, "text": 0}
    for name, msg in sorted(messages.items()):
        cls = rt.message_class(msg.mavlink.msg_id) if msg.mavlink else None
        assert cls is not None and cls.MSG_ID == _pm_class(name).id and cls.CRC_EXTRA == _pm_class(name).crc_extra
        _sweep(msg, cls, _pm_class(name), rt, stats)
        checked += 1
    assert checked == len(messages)
    assert stats["v1.0 dialect"] > 50 and stats["text"] > 10, stats


def _sweep(msg: Message, cls: Any, pm_cls: Any, rt: Any, stats: dict[str, int]) -> None:
    @settings(max_examples=4, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
    @given(_instances(msg, cls), st.integers(0, 255))
    def check(obj: Any, seq: int) -> None:
        theirs = pm_cls(*_pymavlink_args(obj, pm_cls))
        frame = theirs.pack(_mav(seq=seq))
        assert obj.encode() == bytes(theirs.get_payload()), msg.name
        stats["text"] += any(isinstance(v, str) and v for v in obj.to_dict().values())
        assert obj.encode_frame(seq=seq) == frame, msg.name
        _assert_values(rt.decode_message(frame), theirs, list(pm_cls.fieldnames))
        parsed = _mav().parse_buffer(obj.encode_frame(seq=seq))
        assert parsed is not None and len(parsed) == 1, msg.name
        _assert_values(obj, parsed[0], list(pm_cls.fieldnames))
        if cls.MSG_ID < 256:
            v1 = obj.encode_frame(seq=seq, mavlink1=True)
            assert v1[0] == 0xFE and v1[1] == cls.MAVLINK_BASE_LENGTH
            assert v1[6:-2] == obj.encode(truncate=False)[: cls.MAVLINK_BASE_LENGTH]
            parsed1 = _mav().parse_buffer(v1)
            assert parsed1 is not None and len(parsed1) == 1 and parsed1[0].get_msgId() == cls.MSG_ID
            base = [f.name for f in msg.fields if not f.extension]
            _assert_values(obj, parsed1[0], base)
            pm1 = v10.mavlink_map.get(cls.MSG_ID)
            if pm1 is not None and pm1.crc_extra == cls.CRC_EXTRA:  # the same message in the v1.0 dialect
                assert v1 == pm1(*_pymavlink_args(obj, pm1)).pack(_mav(v10.MAVLink, seq=seq)), msg.name
                stats["v1.0 dialect"] += 1
        else:
            with pytest.raises(rt.EncodeError, match="MAVLink 1"):
                obj.encode_frame(mavlink1=True)
        # batch: the zero-filled record decodes to the same columns both ways
        record = obj.encode(truncate=False) * 2
        plain = cls.decode_batch(record, use_numpy=False)
        for f in msg.fields:
            assert _same(list(plain[f.name][1]) if isinstance(plain[f.name][1], tuple) else plain[f.name][1],
                         obj.to_dict()[f.name]), (msg.name, f.name)  # fmt: skip

    check()


def _class_name(module: ModuleType, msg: Message) -> str:
    from codegen.backends.python import naming

    return naming.class_name(msg)


def _payload_struct_name(module: ModuleType, msg: Message) -> str:
    from codegen.backends.python import naming

    return f"_{naming.upper_snake(_class_name(module, msg))}_PAYLOAD"


def test_struct_format_matches_pymavlink_unpacker(common_pkg: tuple[ModuleType, dict[str, Message]]) -> None:
    module, messages = common_pkg
    for name, msg in messages.items():
        layout = getattr(module, _payload_struct_name(module, msg))
        assert isinstance(layout, struct.Struct)
        assert layout.size == _pm_class(name).unpacker.size == msg.mavlink.max_length  # type: ignore[union-attr]
