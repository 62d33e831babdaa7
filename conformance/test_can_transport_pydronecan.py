"""DroneCAN transport against pydronecan: captures built from pydronecan's own transfers, for every data type.

For each message and service type of the ``dronecan`` package's DSDL, a value with random content is split into
frames by pydronecan's ``Transfer.to_frames`` (classic CAN and CAN FD), interleaved with other nodes' transfers
and read back through battgen's reassembler. The transfer must come out with pydronecan's node, type, transfer id
and payload bytes; decoded by battgen's generated class for the whole DSDL tree, it must re-encode to the bytes
pydronecan packs from its own decode of the same frames (``Transfer.from_frames``). Corrupted variants (a flipped
toggle bit, a wrong CRC, a dropped first or last frame, two frames swapped) must give the diagnostic a bus
debugger expects, and the intact transfers around them must still come out.
"""

from __future__ import annotations

import importlib
import os
import random
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from codegen.backends.python.writer import generate
from codegen.frontends import dsdl
from codegen.inputs.can import wire
from codegen.inputs.can.reassembly import Diagnostic, Frame, Reassembler, Transfer
from codegen.inputs.can.records import decode_transfer, registry

dronecan = pytest.importorskip("dronecan")
from dronecan import dsdl as pydsdl  # noqa: E402
from dronecan import transport  # noqa: E402

SPECS = Path(os.path.dirname(dronecan.__file__)) / "dsdl_specs"
# the types as pydronecan loads them (with their transfer CRC seeds), by full name
TYPES = sorted(dronecan.TYPENAMES.items())
ROUNDS = int(os.environ.get("BATTGEN_CAN_ROUNDS", "3"))  # random values per type (more in a long run)


@pytest.fixture(scope="module")
def specs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """battgen's package generated from pydronecan's whole DSDL tree."""
    out = tmp_path_factory.mktemp("can_specs")
    generate(dsdl.parse_dir(SPECS), out / "can_specs")
    sys.path.insert(0, str(out))
    try:
        importlib.invalidate_caches()
        yield "can_specs"
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] == "can_specs"]:
            del sys.modules[name]


def _fill(value: Any, rng: random.Random, depth: int = 0) -> None:
    """Random content for a pydronecan value, within its type's ranges and capacities."""
    if isinstance(value, transport.CompoundValue):
        names = [n for n in value._fields if not n.startswith("_void")]
        if value._is_union:
            if names:
                pick = rng.choice(names)
                transport.switch_union_field(value, pick)
                _fill(value._fields[pick], rng, depth + 1)
            return
        for name in names:
            _fill(value._fields[name], rng, depth + 1)
    elif isinstance(value, transport.ArrayValue):
        t = value._type
        if t.mode == pydsdl.ArrayType.MODE_DYNAMIC:
            for _ in range(rng.randint(0, min(t.max_size, 40 if depth < 2 else 3))):
                item = value.new_item()
                _fill(item, rng, depth + 1)
                if isinstance(item, transport.PrimitiveValue):
                    value.append(item.value)
                else:
                    value.append(item)
        else:
            for item in value:
                _fill(item, rng, depth + 1)
    elif isinstance(value, transport.PrimitiveValue):
        t = value._type
        if t.kind == t.KIND_BOOLEAN:
            value.value = rng.random() < 0.5
        elif t.kind == t.KIND_UNSIGNED_INT:
            value.value = rng.randrange(1 << t.bitlen)
        elif t.kind == t.KIND_SIGNED_INT:
            value.value = rng.randrange(-(1 << (t.bitlen - 1)), 1 << (t.bitlen - 1))
        else:
            value.value = rng.uniform(-1000.0, 1000.0)


def _values(t: Any, rng: random.Random) -> Iterator[tuple[Any, bool]]:
    """Random values of a type: (value, request?) for both halves of a service."""
    modes = ["request", "response"] if t.kind == t.KIND_SERVICE else [None]
    for mode in modes:
        value = transport.CompoundValue(t, _mode=mode)
        _fill(value, rng)
        yield value, mode == "request"


def _transfer(t: Any, value: Any, request: bool, node: int, tid: int, fd: bool) -> Any:
    service = t.kind == t.KIND_SERVICE
    return transport.Transfer(
        transfer_id=tid,
        source_node_id=node,
        dest_node_id=(node % 100) + 1 if service else None,
        payload=value,
        service_not_message=service,
        request_not_response=request,
        transfer_priority=16,
        canfd=fd,
    )


def _frames(transfers: list[Any], rng: random.Random) -> list[Frame]:
    """The frames of several transfers, interleaved the way a bus arbitrates them (order kept per transfer)."""
    queues = [[bytes(f.bytes) for f in tr.to_frames()] for tr in transfers]
    ids = [tr.message_id for tr in transfers]
    fds = [tr.canfd for tr in transfers]
    out: list[Frame] = []
    while any(queues):
        i = rng.choice([k for k, q in enumerate(queues) if q])
        out.append(Frame(len(out), len(out) * 1e-4, ids[i], queues[i].pop(0), True, fds[i]))
    return out


def _signatures() -> dict[tuple[str, int], int]:
    out = {}
    for _, t in TYPES:
        if t.default_dtid is not None:
            out[("service" if t.kind == t.KIND_SERVICE else "message", t.default_dtid)] = t.get_data_type_signature()
    return out


def _run(frames: list[Frame], signatures: dict[tuple[str, int], int]) -> tuple[list[Transfer], list[Diagnostic]]:
    r = Reassembler(signatures)
    events = [e for f in frames for e in r.feed(f)] + list(r.finish(frames[-1].t, frames[-1].index))
    return [e for e in events if isinstance(e, Transfer)], [e for e in events if isinstance(e, Diagnostic)]


def _reference_payload(tr: Any, frames: list[Frame]) -> bytes:
    """pydronecan's own decode of the frames, packed again (its canonical bytes of what it read)."""
    ref_frames = [transport.Frame(f.can_id, f.data, canfd=f.fd) for f in frames]
    back = transport.Transfer()
    back.from_frames(ref_frames)
    bits = back.payload._pack(tao=not tr.canfd)
    if len(bits) & 7:
        bits += "0" * (8 - (len(bits) & 7))
    return bytes(transport.bytes_from_bits(bits))


ROUTABLE = [(name, t) for name, t in TYPES if t.default_dtid is not None]


@pytest.mark.parametrize("fd", [False, True], ids=["classic", "fd"])
@pytest.mark.parametrize(("name", "t"), ROUTABLE, ids=[n for n, _ in ROUTABLE])
def test_every_type_reassembles_and_decodes_like_pydronecan(specs: str, name: str, t: Any, fd: bool) -> None:
    rng = random.Random(f"{name}/{fd}")
    signatures = _signatures()
    known = registry(specs)
    for round_ in range(ROUNDS):
        for value, request in _values(t, rng):
            node = rng.randint(1, 127)
            tid = rng.randrange(32)
            tr = _transfer(t, value, request, node, tid, fd)
            other = transport.Transfer(
                transfer_id=round_,
                source_node_id=(node % 126) + 1,
                transfer_priority=8,
                payload=dronecan.uavcan.protocol.NodeStatus(uptime_sec=round_),
                canfd=fd,
            )
            own = [Frame(0, 0.0, tr.message_id, bytes(f.bytes), True, fd) for f in tr.to_frames()]
            frames = _frames([tr, other], rng)
            transfers, problems = _run(frames, signatures)
            assert [p for p in problems if p.severity != "info"] == [], name
            got = [x for x in transfers if x.id.data_type_id == tr.data_type_id and x.node == node]
            assert len(got) == 1, name
            x = got[0]
            assert (x.transfer_id, x.id.service, x.id.request, x.frames) == (
                tid,
                tr.service_not_message,
                request and tr.service_not_message,
                len(own),
            )
            assert x.payload == bytes(tr.payload), name
            cls = known[(x.id.kind, tr.data_type_id)]
            ours = decode_transfer(cls, x)
            assert ours.encode(tao=not fd) == _reference_payload(tr, own), name


def _multi_frame_value(rng: random.Random) -> Any:
    info = dronecan.uavcan.equipment.power.BatteryInfo(voltage=23.1, current=4.2, battery_id=3, model_name="pack 6S")
    return info


def _capture(corrupt: str) -> tuple[list[Transfer], list[Diagnostic]]:
    """Three BatteryInfo transfers from node 9; the middle one corrupted as named."""
    frames: list[Frame] = []
    for tid in range(3):
        tr = transport.Transfer(transfer_id=tid, source_node_id=9, payload=_multi_frame_value(random.Random(tid)))
        data = [bytes(f.bytes) for f in tr.to_frames()]
        assert len(data) > 2
        if tid == 1:
            if corrupt == "toggle":
                data[1] = data[1][:-1] + bytes([data[1][-1] ^ wire.TAIL_TOGGLE])
            elif corrupt == "crc":
                data[0] = bytes([data[0][0] ^ 0xFF]) + data[0][1:]
            elif corrupt == "drop-first":
                data = data[1:]
            elif corrupt == "drop-last":
                data = data[:-1]
            elif corrupt == "swap":
                data[1], data[2] = data[2], data[1]
        for d in data:
            frames.append(Frame(len(frames), len(frames) * 1e-3, tr.message_id, d))
    return _run(frames, _signatures())


@pytest.mark.parametrize(
    ("corrupt", "code"),
    [
        ("toggle", "can-toggle"),
        ("crc", "can-crc"),
        ("drop-first", "can-missing-start"),
        ("drop-last", "can-missing-end"),
        ("swap", "can-toggle"),
    ],
)
def test_corrupted_transfer_gives_its_diagnostic(corrupt: str, code: str) -> None:
    transfers, problems = _capture(corrupt)
    assert code in {p.code for p in problems}
    assert [t.transfer_id for t in transfers] == [0, 2]  # the damaged one dropped, its neighbours intact
    # pydronecan refuses the same damaged frames too (its TransferError), where it checks that kind
    if corrupt in ("toggle", "crc", "swap"):
        tr = transport.Transfer(transfer_id=1, source_node_id=9, payload=_multi_frame_value(random.Random(1)))
        data = [bytes(f.bytes) for f in tr.to_frames()]
        if corrupt == "toggle":
            data[1] = data[1][:-1] + bytes([data[1][-1] ^ wire.TAIL_TOGGLE])
        elif corrupt == "crc":
            data[0] = bytes([data[0][0] ^ 0xFF]) + data[0][1:]
        else:
            data[1], data[2] = data[2], data[1]
        with pytest.raises(transport.TransferError):
            transport.Transfer().from_frames([transport.Frame(tr.message_id, d) for d in data])


def test_crc_mismatch_names_the_signature() -> None:
    _, problems = _capture("crc")
    crc = next(p for p in problems if p.code == "can-crc")
    signature = dronecan.TYPENAMES["uavcan.equipment.power.BatteryInfo"].get_data_type_signature()
    assert f"0x{signature:016X}" in crc.message and crc.node == 9 and crc.data_type_id == 1092


def test_split_transfer_equals_pydronecan_to_frames() -> None:
    rng = random.Random(7)
    for _, t in ROUTABLE[:40]:
        for value, request in _values(t, rng):
            for fd in (False, True):
                tr = _transfer(t, value, request, 5, 17, fd)
                ours = wire.split_transfer(bytes(tr.payload), t.get_data_type_signature(), 17, fd=fd)
                # pydronecan pads FD payloads inside to_frames; its .payload is the unpadded bytes
                assert ours == [bytes(f.bytes) for f in tr.to_frames()], t.full_name


def test_identifier_fields_equal_pydronecan() -> None:
    rng = random.Random(3)
    for _ in range(2000):
        can_id = rng.randrange(1 << 29)
        ref = transport.Transfer()
        ref.message_id = can_id
        ours = wire.parse_id(can_id)
        assert (ours.priority, ours.service, ours.data_type_id, ours.source) == (
            ref.transfer_priority,
            ref.service_not_message,
            ref.data_type_id,
            ref.source_node_id,
        )
        if ours.service:
            assert (ours.destination, ours.request) == (ref.dest_node_id, ref.request_not_response)
        elif ours.anonymous:
            assert ours.discriminator == ref.discriminator
