"""Fuzzing the generated decoders: DroneCAN, uORB and MAVLink decode on random and mutated bytes.

Each decoder either raises its DecodeError (a ValueError) or returns an instance the encoder takes, and
decoding that encoding gives the same values (decode . encode . decode == decode); the MAVLink stream
parser finds the same frames fed whole or in pieces, strict or not (tests/fuzz/targets.py).
"""

from __future__ import annotations

from budget import fuzz_settings
from fuzz_inputs import mutated
from hypothesis import given
from hypothesis import strategies as st
from targets import TARGETS

from generated.mavlink import BatteryStatus as MavBatteryStatus
from generated.uorb import BatteryStatus

_FRAMES = [
    MavBatteryStatus(id=i, voltages=[4000 + i] * 10, current_consumed=-i, battery_remaining=i).encode_frame(
        seq=i, sysid=1, compid=1, mavlink1=i % 2 == 1
    )
    for i in range(4)
]


@fuzz_settings(ci=300)
@given(st.binary(max_size=120))
def test_fuzz_dronecan_decode(data: bytes) -> None:
    TARGETS["decode-dronecan"](data)


@fuzz_settings(ci=200)
@given(st.one_of(st.binary(min_size=168, max_size=168), mutated([BatteryStatus(voltage_v=12.0).encode()])))
def test_fuzz_uorb_decode(data: bytes) -> None:
    TARGETS["decode-uorb"](data)


@fuzz_settings(ci=300)
@given(st.one_of(st.binary(max_size=300), mutated([b"".join(_FRAMES), _FRAMES[0], _FRAMES[1] + b"\x00" + _FRAMES[2]])))
def test_fuzz_mavlink_decode_and_stream(data: bytes) -> None:
    TARGETS["decode-mavlink"](data)
