"""The runtime helpers the generated DroneCAN codecs call for a dynamic uint8 array (generated/_dronecan.py):
its length in stream order, then its bytes, or with TAO its bytes alone -- against pydronecan's bits."""

from __future__ import annotations

import dronecan
import pytest
from dronecan import transport
from hypothesis import given, settings
from hypothesis import strategies as st

from generated import _dronecan as dc
from generated.dronecan.uavcan.equipment.power import BatteryInfo


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 40), st.data())
def test_stream_order_round_trips(width: int, data: st.DataObject) -> None:
    value = data.draw(st.integers(0, (1 << width) - 1))
    assert dc.unstream(dc.stream(value, width), width) == value
    if width <= 8:
        assert dc.stream(value, width) == value  # a byte or less is written as it stands
    elif width == 16:
        assert dc.stream(value, 16) == ((value & 0xFF) << 8) | (value >> 8)  # low byte first


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=31), st.booleans())
def test_bytes_round_trip_and_match_pydronecan(name: bytes, tao: bool) -> None:
    acc = dc.put_bytes(1, name, 31, tao, "X.name")
    bits = acc.bit_length() - 1
    assert bits == len(name) * 8 + (0 if tao else 5)
    got, rem = dc.get_bytes(acc ^ (1 << bits), bits, 31, tao, "X.name")
    assert (got, rem) == (name, 0)
    # the helpers are the nested and CAN FD path of BatteryInfo: its bytes are pydronecan's
    ours = BatteryInfo(model_name=name).encode(tao=tao)
    ref = dronecan.uavcan.equipment.power.BatteryInfo(model_name=name)
    assert ours[23:] == bytes(transport.bytes_from_bits(ref._pack(tao)))[23:]  # the array after the head
    assert BatteryInfo.decode(ours, tao=tao).model_name == name


def test_errors_name_the_field() -> None:
    with pytest.raises(dc.EncodeError, match=r"X.name: length 32 exceeds capacity 31"):
        dc.put_bytes(1, bytes(32), 31, False, "X.name")
    with pytest.raises(dc.DecodeError, match=r"X.name \(length\): input ends inside this field \(3 bits left"):
        dc.get_bytes(0b101, 3, 31, False, "X.name")
    with pytest.raises(dc.DecodeError, match=r"X.name: input ends inside this field \(8 bits left, 16 needed"):
        dc.get_bytes((2 << 8) | 0xAB, 13, 31, False, "X.name")
    with pytest.raises(dc.DecodeError, match=r"X.name: length 3 exceeds capacity 2"):
        dc.get_bytes(0xABCDEF, 24, 2, True, "X.name")
