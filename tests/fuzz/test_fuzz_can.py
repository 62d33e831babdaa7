"""Fuzzing the DroneCAN transport: any sequence of frames, any identifiers and tail bytes, never an exception.

The reassembler must hand out transfers and diagnostics for whatever a damaged or hostile bus carries, with its
state bounded (transfers in progress and their length), and what it hands out must be consistent: a transfer's
payload never longer than its frames could carry.
"""

from __future__ import annotations

from budget import crashers, fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from codegen.inputs.can import reassembly, wire
from codegen.inputs.can.reassembly import Diagnostic, Frame, Reassembler, Transfer

SIGNATURES = {
    ("message", 1092): 0x249C26548A711966,
    ("message", 20004): 0x7D7F49FC75484882,
}  # BatteryInfo, BatteryInfoAux

frames = st.lists(
    st.tuples(
        st.integers(0, (1 << 29) - 1) | st.sampled_from([wire.message_id(1092, 10), wire.message_id(20004, 10)]),
        st.binary(min_size=0, max_size=64),
        st.booleans(),
        st.floats(0, 10, allow_nan=False),
    ),
    max_size=200,
)


def _feed(items: list[tuple[int, bytes, bool, float]]) -> list[Transfer | Diagnostic]:
    r = Reassembler(SIGNATURES)
    out: list[Transfer | Diagnostic] = []
    t = 0.0
    for i, (can_id, data, extended, dt) in enumerate(items):
        t += dt
        out.extend(r.feed(Frame(i, t, can_id, data, extended, len(data) > 8)))
        assert len(r._pending) <= reassembly.MAX_PENDING
    out.extend(r.finish(t, len(items)))
    return out


@fuzz_settings(ci=300)
@given(frames)
def test_any_frames_give_transfers_and_diagnostics(items: list[tuple[int, bytes, bool, float]]) -> None:
    for event in _feed(items):
        if isinstance(event, Transfer):
            assert len(event.payload) <= event.frames * 63
            assert event.frame <= event.last_frame
        else:
            assert event.code.startswith("can-") and event.message


def test_saved_crashers_replay() -> None:
    for path in crashers("can"):
        data = path.read_bytes()
        items = [
            (int.from_bytes(data[i : i + 4], "little") & 0x1FFFFFFF, data[i + 4 : i + 12], True, 0.001)
            for i in range(0, len(data) - 12, 12)
        ]
        _feed(items)
