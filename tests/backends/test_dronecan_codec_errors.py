"""Generated DroneCAN codecs: error paths, float16 rounding, TAO switch, ids and the transfer CRC.

Small DSDL definitions written here exercise what the bundled schemas cannot reach (a length
prefix wider than the capacity, a union tag with unused values); conformance/ compares the
happy paths with pydronecan.
"""

from __future__ import annotations

import importlib
import random
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from codegen.backends.python.writer import generate
from codegen.frontends import dsdl

ROOT = Path(__file__).resolve().parents[2]

DEFINITIONS = {
    "Fixed.uavcan": "uint4 a\nvoid4\nint16 b\n",
    "Bounded.uavcan": "uint8[<=30] data\nbool flag\n",
    "Choice.uavcan": "@union\nuint8 small\nfloat32 real\nuint8[<=4] raw\n",
    "Tail.uavcan": "uint3 head\ntest.Choice choice\nfloat16[<=5] cells\n",
    "Halves.uavcan": "float16 sat\ntruncated float16 trunc\n",
}


@pytest.fixture(scope="module")
def pkg(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    base = tmp_path_factory.mktemp("dc_unit")
    (base / "dsdl" / "test").mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (base / "dsdl" / "test" / name).write_text(text)
    schema = dsdl.parse_dir(base / "dsdl").merged(dsdl.parse_dir(ROOT / "schemas" / "dronecan"))
    generate(schema, base / "out" / "dc_unit")
    sys.path.insert(0, str(base / "out"))
    try:
        test = importlib.import_module("dc_unit.dronecan.test")
        power = importlib.import_module("dc_unit.dronecan.uavcan.equipment.power")
        runtime = importlib.import_module("dc_unit._dronecan")
        yield {"test": test, "power": power, "rt": runtime}
    finally:
        sys.path.remove(str(base / "out"))
        for name in [n for n in sys.modules if n.split(".")[0] == "dc_unit"]:
            del sys.modules[name]


def _error(rt: ModuleType, fn: Any, *args: Any, **kwargs: Any) -> str:
    with pytest.raises(rt.DecodeError) as info:
        fn(*args, **kwargs)
    return str(info.value)


def test_truncated_input_names_the_field(pkg: dict[str, Any]) -> None:
    info = pkg["power"].BatteryInfo
    payload = info(voltage=12.0, model_name=b"pack").encode()
    assert "BatteryInfo.current: input ends inside this field" in _error(pkg["rt"], info.decode, payload[:5])
    assert "BatteryInfo.model_instance_id" in _error(pkg["rt"], info.decode, payload[:20])
    assert "BatteryInfo.model_name (length)" in _error(pkg["rt"], info.decode, payload[:23], tao=False)
    fixed = pkg["test"].Fixed
    assert "Fixed.b" in _error(pkg["rt"], fixed.decode, b"\x10\x00")


def test_length_over_capacity(pkg: dict[str, Any]) -> None:
    info = pkg["power"].BatteryInfo
    head = info().encode()
    msg = _error(pkg["rt"], info.decode, head + b"x" * 40)
    assert msg == "BatteryInfo.model_name: length 40 exceeds capacity 31"
    bounded = pkg["test"].Bounded
    # 5-bit length 31 > capacity 30
    assert _error(pkg["rt"], bounded.decode, bytes([31 << 3]) + bytes(40)) == (
        "Bounded.data: length 31 exceeds capacity 30"
    )
    with pytest.raises(pkg["rt"].EncodeError, match=r"Bounded\.data: length 31 exceeds capacity 30"):
        bounded(data=bytes(31)).encode()
    with pytest.raises(pkg["rt"].EncodeError, match=r"BatteryInfo\.model_name: length 32 exceeds capacity 31"):
        info(model_name=bytes(32)).encode()


def test_bad_union_tag_and_union_field(pkg: dict[str, Any]) -> None:
    choice = pkg["test"].Choice
    assert _error(pkg["rt"], choice.decode, bytes([0b11 << 6, 0])) == "Choice: union tag 3 is not one of 0..2"
    value = choice(real=1.5)
    assert choice.decode(value.encode()) == value
    value.union_field = "nope"  # stored as given: validate() reports it, encode() refuses it
    with pytest.raises(pkg["rt"].EncodeError, match=r"Choice\.union_field: 'nope' is not a field of Choice"):
        value.encode()


def test_trailing_bytes_rejected_padding_bits_accepted(pkg: dict[str, Any]) -> None:
    fixed = pkg["test"].Fixed
    data = fixed(a=9, b=-2).encode()
    assert data == bytes([0x90, 0xFE, 0xFF])
    assert "Fixed: 1 byte(s) beyond the end of the message" in _error(pkg["rt"], fixed.decode, data + b"\x00")
    # void bits are ignored on decode, written as zeros on encode
    assert fixed.decode(bytes([0x9F, 0xFE, 0xFF])) == fixed(a=9, b=-2)
    bounded = pkg["test"].Bounded
    data = bounded(data=b"\x01", flag=True).encode()
    assert data == bytes([0b00001_000, 0b00001_1_00])  # length 1, the byte, the flag, 2 padding bits
    assert bounded.decode(bytes([0b00001_000, 0b00001_1_11])) == bounded(data=b"\x01", flag=True)
    assert "Bounded: 1 byte(s) beyond" in _error(pkg["rt"], bounded.decode, data + b"\x00")


def test_tail_array_optimisation_switch(pkg: dict[str, Any]) -> None:
    tail, choice = pkg["test"].Tail, pkg["test"].Choice
    value = tail(head=5, choice=choice(small=7), cells=[1.0, -2.0])
    with_tao, without = value.encode(), value.encode(tao=False)
    assert without[0] == with_tao[0] and without[1:] != with_tao[1:]  # a 3-bit length prefix after 13 bits
    assert tail.decode(with_tao) == value
    assert tail.decode(without, tao=False) == value
    assert "Tail.cells: input ends inside an element" in _error(pkg["rt"], tail.decode, with_tao + b"\x00")
    info = pkg["power"].BatteryInfo
    named = info(model_name=b"abc")
    assert named.encode()[-3:] == b"abc"
    assert info.decode(named.encode(tao=False), tao=False) == named


def test_float16_rounding_and_special_values(pkg: dict[str, Any]) -> None:
    halves = pkg["test"].Halves

    def bits(value: float) -> tuple[int, int]:
        data = halves(sat=value, trunc=value).encode()
        return data[0] | data[1] << 8, data[2] | data[3] << 8

    assert bits(1.00048828125) == (0x3C01, 0x3C01)  # a tie rounds away from zero (struct 'e' gives 0x3C00)
    assert bits(-1.00048828125) == (0xBC01, 0xBC01)
    assert bits(float("nan")) == (0x7FFF, 0x7FFF)
    assert bits(float("inf")) == (0x7C00, 0x7C00)  # both keep infinity (DSDL v0: saturation preserves it)
    assert bits(float("-inf")) == (0xFC00, 0xFC00)
    assert bits(65520.0) == (0x7BFF, 0x7C00)  # finite beyond 65504: saturated clamps, truncated overflows
    assert bits(-1e9) == (0xFBFF, 0xFC00)
    assert bits(65519.0) == (0x7BFF, 0x7C00)
    assert bits(5.960464477539063e-08) == (0x0001, 0x0001)
    back = halves.decode(halves(sat=float("nan"), trunc=float("-inf")).encode())
    assert back.sat != back.sat and back.trunc == float("-inf")


def test_random_bytes_raise_only_decode_error(pkg: dict[str, Any]) -> None:
    rng = random.Random(7)
    classes = [getattr(pkg["test"], n) for n in ("Fixed", "Bounded", "Choice", "Tail", "Halves")]
    classes += [pkg["power"].BatteryInfo, pkg["power"].CircuitStatus, pkg["power"].PrimaryPowerSupplyStatus]
    for cls in classes:
        for _ in range(300):
            data = bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 40)))
            for tao in (True, False):
                try:
                    obj = cls.decode(data, tao=tao)
                except pkg["rt"].DecodeError:
                    continue
                assert isinstance(obj, cls)
                assert cls.decode(obj.encode(tao=tao), tao=tao).encode(tao=tao) == obj.encode(tao=tao)


def test_ids_signature_and_crc(pkg: dict[str, Any]) -> None:
    info = pkg["power"].BatteryInfo
    assert info.DATA_TYPE_ID == 1092
    assert info.DATA_TYPE_SIGNATURE == 0x249C26548A711966
    assert pkg["test"].Fixed.DATA_TYPE_ID is None
    rt = pkg["rt"]
    assert rt.crc16(b"123456789") == 0x29B1  # CRC-16/CCITT-FALSE check value
    assert rt.transfer_crc(0, b"") == rt.crc16(bytes(8))
    assert issubclass(rt.DecodeError, ValueError)
