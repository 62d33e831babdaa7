"""Cyphal/CAN on the wire: captures whose frames pycyphal made, read by ``battgen can``.

The values are pycyphal's own objects (classes nunavut generates from the bundled DSDL, serialized by
``pycyphal.dsdl.serialize``), their transfers cut into frames by pycyphal's Cyphal/CAN transfer serializer (CAN
identifiers compiled by its ``MessageCANID``, tail bytes by its ``CyphalFrame``), written as candump logs by
python-can. battgen must report each node's battery transfers with the values pycyphal sent, and the damage
pycyphal's own reassembler refuses (a toggle error, a CRC error, a lost frame) as located problems.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from can_logs import write_capture

from codegen.cli.main import main
from codegen.inputs.can import cyphal_wire
from codegen.inputs.can.cyphal_reassembly import CyphalReassembler, MixedReassembler
from codegen.inputs.can.reassembly import Diagnostic, Frame, Transfer

can = pytest.importorskip("can")
pytest.importorskip("pycyphal")
pytest.importorskip("nunavut")
import pycyphal.dsdl  # noqa: E402
from pycyphal.transport import Priority  # noqa: E402
from pycyphal.transport.can._identifier import MessageCANID  # noqa: E402
from pycyphal.transport.can._session._transfer_sender import serialize_transfer  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
STATUS, SOURCE, PARAMETERS = 4096, 4097, 4098
SUBJECTS = [f"--cyphal-subject={STATUS}=status", f"--cyphal-subject={SOURCE}=energy_source"]
SUBJECTS += [f"--cyphal-subject={PARAMETERS}=reg.udral.service.battery.Parameters.0.3"]
NODES = {12: 3.7, 13: 3.9}  # node -> its cells' voltage
CYCLES = 3
CLASSIC, FD = 7, 63  # bytes of payload a frame carries (its tail byte aside)


@pytest.fixture(scope="module")
def dsdl(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The nunavut-generated classes of the bundled Cyphal types, as pycyphal users have them."""
    out = tmp_path_factory.mktemp("pycyphal")
    roots = [ROOT / "schemas" / "cyphal" / "reg", ROOT / "schemas" / "cyphal" / "uavcan"]
    pycyphal.dsdl.compile_all(roots, output_directory=out)
    sys.path.insert(0, str(out))
    try:
        import reg.udral.physics.electricity as electricity
        import reg.udral.service.battery as battery
        import uavcan.si.unit.electric_charge as charge
        import uavcan.si.unit.electric_current as current
        import uavcan.si.unit.energy as energy
        import uavcan.si.unit.temperature as temperature
        import uavcan.si.unit.voltage as voltage
    finally:
        sys.path.remove(str(out))
    return {
        "battery": battery,
        "electricity": electricity,
        "charge": charge,
        "current": current,
        "energy": energy,
        "temperature": temperature,
        "voltage": voltage,
    }


def _status(d: Any, cell: float, cycle: int) -> Any:
    t = d["temperature"].Scalar_1_0
    return d["battery"].Status_0_2(
        temperature_min_max=[t(kelvin=298.0 + cycle), t(kelvin=305.5)],
        available_charge=d["charge"].Scalar_1_0(coulomb=36000.0 - 100 * cycle),
        error=d["battery"].Error_0_1(value=d["battery"].Error_0_1.CELL_UNDERVOLTAGE if cycle == 2 else 0),
        cell_voltages=[cell] * 6,
    )


def _source(d: Any, cycle: int) -> Any:
    e = d["electricity"]
    power = e.Power_0_1(current=d["current"].Scalar_1_0(ampere=-12.5), voltage=d["voltage"].Scalar_1_0(volt=22.2))
    source = e.Source_0_1(
        power=power,
        energy=d["energy"].Scalar_1_0(joule=400_000.0 - cycle),
        full_energy=d["energy"].Scalar_1_0(joule=500_000.0),
    )
    return e.SourceTs_0_1(value=source)


def _frames(obj: Any, subject: int, node: int, tid: int, mtu: int) -> list[tuple[int, bytes]]:
    """pycyphal's frames of one message transfer: (CAN id, data with the tail byte)."""
    payload = [memoryview(bytes(b)) for b in pycyphal.dsdl.serialize(obj)]
    can_id = MessageCANID(Priority.NOMINAL, node, subject).compile(payload)
    out = []
    for frame in serialize_transfer(can_id, tid, payload, mtu):
        compiled = frame.compile()
        out.append((compiled.identifier, bytes(compiled.data)))
    return out


def _bus(d: Any, mtu: int = CLASSIC) -> list[tuple[int, bytes]]:
    frames: list[tuple[int, bytes]] = []
    for cycle in range(CYCLES):
        for node, cell in NODES.items():
            frames += _frames(_status(d, cell, cycle), STATUS, node, cycle, mtu)
            frames += _frames(_source(d, cycle), SOURCE, node, cycle, mtu)
    return frames


def _capture(path: Path, frames: list[tuple[int, bytes]], *, fd: bool = False) -> Path:
    messages = [
        can.Message(timestamp=1_700_000_000.0 + 0.001 * i, arbitration_id=i_d, is_extended_id=True, data=data, is_fd=fd)
        for i, (i_d, data) in enumerate(frames)
    ]
    return write_capture(path, messages)


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[dict[str, Any]], dict[str, Any]]:
    code = main(["can", "--records", "--format", "json", *args])
    lines = capsys.readouterr().out.splitlines()
    records = [json.loads(x) for x in lines if x.startswith('{"t"')]
    report = json.loads("\n".join(x for x in lines if not x.startswith('{"t"')))["captures"][0]
    return code, records, report


@pytest.mark.parametrize("mtu", [CLASSIC, FD], ids=["classic", "fd"])
def test_battery_transfers_are_reported_per_node_with_pycyphal_values(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str], mtu: int
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl, mtu), fd=mtu == FD)
    code, records, report = _run(capsys, str(path), *SUBJECTS)
    assert code == 0 and report["problem_counts"] == {}
    streams = {(s["node"], s["data_type_id"]): s for s in report["streams"]}
    for node in NODES:
        assert streams[(node, STATUS)]["name"] == "reg.udral.service.battery.Status.0.2"
        assert streams[(node, SOURCE)]["name"] == "reg.udral.physics.electricity.SourceTs.0.1"
        assert streams[(node, STATUS)]["count"] == CYCLES and streams[(node, STATUS)]["protocol"] == "cyphal"
        assert streams[(node, STATUS)]["kind"] == "subject"
    statuses = [r for r in records if r["subject"] == STATUS]
    assert len(statuses) == CYCLES * len(NODES)
    for r in statuses:
        cycle = statuses.index(r) // len(NODES)
        sent = _status(dsdl, NODES[r["node"]], cycle)
        got = r["message"]
        assert got["temperature_min_max"] == [{"kelvin": t.kelvin} for t in sent.temperature_min_max]
        assert math.isclose(got["available_charge"]["coulomb"], sent.available_charge.coulomb)
        assert got["error"]["value"] == sent.error.value
        assert got["cell_voltages"] == pytest.approx(list(sent.cell_voltages))
    sources = [r["message"]["value"]["power"] for r in records if r["subject"] == SOURCE]
    assert sources and all(
        p == {"current": {"ampere": -12.5}, "voltage": {"volt": pytest.approx(22.2)}} for p in sources
    )


def _reassemble(frames: list[tuple[int, bytes]], reassembler: Any = None) -> list[Transfer | Diagnostic]:
    r = reassembler or CyphalReassembler()
    out: list[Transfer | Diagnostic] = []
    for i, (can_id, data) in enumerate(frames):
        out.extend(r.feed(Frame(i, i * 0.001, can_id, data, fd=len(data) > 8)))
    out.extend(r.finish(len(frames) * 0.001, len(frames)))
    return out


def _pycyphal_accepts(frames: list[tuple[int, bytes]]) -> int:
    """How many transfers pycyphal's own reassembler completes from these frames (its verdict on damage)."""
    from pycyphal.transport import Timestamp, TransferFrom
    from pycyphal.transport.can._frame import CyphalFrame
    from pycyphal.transport.can._session._transfer_reassembler import TransferReassembler
    from pycyphal.transport.can.media import DataFrame, FrameFormat

    reassembler = TransferReassembler(source_node_id=12, extent_bytes=4800)
    done = 0
    for i, (can_id, data) in enumerate(frames):
        frame = CyphalFrame.parse(DataFrame(FrameFormat.EXTENDED, can_id, bytearray(data)))
        if frame is None:
            continue
        stamp = Timestamp(system_ns=0, monotonic_ns=i * 1_000_000)
        result = reassembler.process_frame(stamp, Priority.NOMINAL, frame, 2_000_000_000)
        done += isinstance(result, TransferFrom)
    return done


def test_damage_is_refused_as_pycyphal_refuses_it(dsdl: Any) -> None:
    """A multi-frame transfer with one payload byte changed (CRC), a toggle bit flipped, a frame lost: no
    transfer, a located problem, and pycyphal's reassembler agreeing that nothing valid arrived."""
    good = _frames(_status(dsdl, 3.7, 0), STATUS, 12, 7, CLASSIC)
    assert len(good) > 2 and _pycyphal_accepts(good) == 1
    flipped_byte = [good[0], (good[1][0], bytes([good[1][1][0] ^ 0x10]) + good[1][1][1:]), *good[2:]]
    flipped_toggle = [good[0], (good[1][0], good[1][1][:-1] + bytes([good[1][1][-1] ^ 0x20])), *good[2:]]
    lost = [good[0], *good[2:]]
    for damaged, code in ((flipped_byte, "can-crc"), (flipped_toggle, "can-toggle"), (lost, "can-toggle")):
        assert _pycyphal_accepts(damaged) == 0
        events = _reassemble(damaged)
        assert not [e for e in events if isinstance(e, Transfer)]
        problems = [e for e in events if isinstance(e, Diagnostic)]
        assert problems[0].code == code and problems[0].node == 12 and problems[0].data_type_id == STATUS
        assert "Cyphal subject 4096 from node 12" in problems[0].message


def test_crc_error_in_a_capture_is_located_and_counted(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    frames = _bus(dsdl)
    can_id, data = frames[1]  # the second frame of node 12's first Status
    frames[1] = (can_id, bytes([data[0] ^ 0xFF]) + data[1:])
    code, records, report = _run(capsys, str(_capture(tmp_path / "bad.log", frames)), *SUBJECTS)
    assert code == 1 and report["problem_counts"] == {"can-crc": 1}
    (problem,) = report["problems"]
    assert problem["frame"] == 0 and problem["node"] == 12 and "CRC 0x" in problem["message"]
    assert len([r for r in records if r["subject"] == STATUS]) == CYCLES * len(NODES) - 1


def test_wire_layout_is_pycyphal_s() -> None:
    """Our identifier parsing and our frame splitting (used by the documentation's example) against pycyphal's."""
    from pycyphal.transport.can._identifier import CANID

    payload = bytes(range(150))
    for subject, node in ((0, 0), (4096, 12), (8191, 127)):
        can_id = MessageCANID(Priority.SLOW, node, subject).compile([memoryview(payload)])
        ours = cyphal_wire.parse_id(can_id)
        theirs = CANID.parse(can_id)
        assert ours is not None and theirs is not None
        assert (ours.data_type_id, ours.source, ours.priority) == (subject, node, int(Priority.SLOW))
        assert cyphal_wire.message_id(subject, node, int(Priority.SLOW)) == can_id
        for mtu, fd in ((CLASSIC, False), (FD, True)):
            for size in (0, 5, 7, 8, 13, 60, 62, 63, 64, 150):
                frames = [
                    bytes(f.compile().data) for f in serialize_transfer(can_id, 9, [memoryview(payload[:size])], mtu)
                ]
                assert cyphal_wire.split_transfer(payload[:size], 9, fd=fd) == frames, (size, mtu)


def test_a_mixed_bus_is_told_apart_by_the_start_toggle(dsdl: Any) -> None:
    """DroneCAN's start frames clear the toggle bit, Cyphal's set it: a bus of both gives each its transfers."""
    from codegen.inputs.can import wire

    cyphal = _frames(_status(dsdl, 3.7, 0), STATUS, 12, 3, CLASSIC)
    dronecan_payload = bytes(range(20))
    dronecan = [(wire.message_id(1092, 40), f) for f in wire.split_transfer(dronecan_payload, 0x1234, 3)]
    interleaved = [f for pair in zip(cyphal, dronecan, strict=False) for f in pair] + cyphal[len(dronecan) :]
    events = _reassemble(interleaved, MixedReassembler({("message", 1092): 0x1234}))
    transfers = [e for e in events if isinstance(e, Transfer)]
    assert [e for e in events if isinstance(e, Diagnostic)] == []
    assert {(t.id.protocol, t.node, t.id.data_type_id) for t in transfers} == {
        ("cyphal", 12, STATUS),
        ("dronecan", 40, 1092),
    }
    assert next(t.payload for t in transfers if t.id.protocol == "dronecan") == dronecan_payload


def test_anonymous_and_foreign_frames() -> None:
    anonymous = cyphal_wire.message_id(7509, 5) | cyphal_wire.ANONYMOUS_BIT
    events = _reassemble([(anonymous, bytes([1, 2, 0xE0]))])
    (transfer,) = events
    assert isinstance(transfer, Transfer) and transfer.id.anonymous
    multi = [(anonymous, f) for f in cyphal_wire.split_transfer(bytes(20), 0)]
    assert next(e.code for e in _reassemble(multi) if isinstance(e, Diagnostic)) == "can-anonymous"
    foreign = cyphal_wire.message_id(10, 5) | cyphal_wire.RESERVED_23  # a DroneCAN identifier, not Cyphal's
    (note,) = _reassemble([(foreign, bytes([0xE0]))] * 3)
    assert isinstance(note, Diagnostic) and note.code == "can-foreign-id" and note.severity == "info"


def test_bad_subject_options_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "x.log"
    path.write_text("(1.0) can0 1070000C#E0\n")
    for option, expected in (
        ("4096", "expected ID=TYPE"),
        ("9000=status", "subject id 0..8191"),
        ("4096=reg.udral.service.battery.Statuz", "did you mean"),
    ):
        assert main(["can", str(path), "--cyphal-subject", option]) == 2
        err = capsys.readouterr().err
        assert expected in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_validate_checks_each_node_s_cyphal_battery_status(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``battgen validate`` on a Cyphal/CAN capture: the message the first subject names, every node's records
    located by node and frame, the values pycyphal sent; a damaged transfer is an error (exit 1)."""
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["validate", "--format", "json", *SUBJECTS, str(path)])
    doc = json.loads(capsys.readouterr().out)
    (report,) = doc["files"]
    assert code == 0 and doc["message"] == "cyphal.reg.udral.service.battery.Status_0_2"
    assert report["records"] == CYCLES * len(NODES) and report["errors"] == 0
    stream = next(n for n in report["notices"] if n["kind"] == "stream")
    assert "node 12: 3, node 13: 3" in stream["message"]
    frames = _bus(dsdl)
    frames[1] = (frames[1][0], bytes([frames[1][1][0] ^ 0xFF]) + frames[1][1][1:])
    bad = _capture(tmp_path / "bad.log", frames)
    assert main(["validate", "--format", "json", *SUBJECTS, str(bad)]) == 1
    (report,) = json.loads(capsys.readouterr().out)["files"]
    assert report["records"] == CYCLES * len(NODES) - 1 and report["errors"] == 1


def test_validate_without_the_subject_of_its_message_says_so(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    message = "cyphal.reg.udral.service.battery.Parameters_0_3"
    assert main(["validate", "--message", message, f"--cyphal-subject={STATUS}=status", str(path)]) == 2
    err = capsys.readouterr().err
    assert "expected --cyphal-subject ID=reg.udral.service.battery.Parameters.0.3" in err and "Traceback" not in err
    # read as DroneCAN, the capture's start frames are refused, with a word on how to read it as Cyphal
    assert main(["can", str(path)]) == 1
    assert "can-cyphal-like" in capsys.readouterr().out


def test_subject_types_by_name_port_and_older_namespace() -> None:
    """A TYPE is a DSDL name (version optional: the newest), a UDRAL battery port (UDRAL's or PX4's name for
    it), or a name of the older reg.drone namespace NXP's BMS publishes, read as its reg.udral twin."""
    from codegen.inputs.can.cyphal_ports import cyphal_classes, dsdl_name, subject_table

    classes = cyphal_classes("generated")
    table = subject_table(
        [
            "1=reg.udral.service.battery.Status.0.2",
            "2=reg.udral.service.battery.Status",
            "3=reg.udral.service.battery.Status.0",
            "4=status",
            "5=battery_status",
            "6=reg.drone.service.battery.Status.0.2",
            "7=energy_source",
            "8=battery_parameters",
        ],
        classes,
    )
    names = {port: dsdl_name(cls) for port, cls in table.items()}
    assert {names[p] for p in range(1, 7)} == {"reg.udral.service.battery.Status.0.2"}
    assert names[7] == "reg.udral.physics.electricity.SourceTs.0.1"
    assert names[8] == "reg.udral.service.battery.Parameters.0.3"
