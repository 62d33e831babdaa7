"""``battgen can`` names and CRC-checks every standard DroneCAN type of the shipped DSDL tree, not only the
battery types the generated package decodes: a bus's NodeStatus, GetNodeInfo, parameter and file transfers,
made by pydronecan's own transport, are named, their multi-frame CRCs checked (a damaged one is a can-crc
error), and none is an unknown type."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from can_logs import write_capture

from codegen.apps.can.known_types import shipped_tree, standard_types
from codegen.cli.main import main

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")
from dronecan import transport  # noqa: E402

NODE = 42


def _payloads() -> list[tuple[Any, str]]:
    """(payload, kind) of traffic every DroneCAN node and its tools send."""
    protocol = dronecan.uavcan.protocol
    info = protocol.GetNodeInfo.Response(name="org.example.battery", software_version=protocol.SoftwareVersion(major=1))
    return [
        (protocol.NodeStatus(uptime_sec=12, health=0, mode=0), "message"),
        (info, "response"),  # a multi-frame service response: its CRC needs GetNodeInfo's signature
        (protocol.param.GetSet.Request(index=3, name="BATT_CAPACITY"), "request"),
        (protocol.file.Read.Request(offset=0, path=protocol.file.Path(path="firmware/battery.bin")), "request"),
    ]


def _capture(path: Path, *, damage: int | None = None) -> Path:
    messages = []
    t = 1_700_000_000.0
    for n, (payload, kind) in enumerate(_payloads()):
        options: dict[str, Any] = {}
        if kind != "message":
            options = {"dest_node_id": 10, "request_not_response": kind == "request", "service_not_message": True}
        tr = transport.Transfer(transfer_id=n, source_node_id=NODE, payload=payload, transfer_priority=24, **options)
        for k, frame in enumerate(tr.to_frames()):
            data = bytes(frame.bytes)
            if damage == n and k == 0:
                data = bytes([data[0] ^ 0x33]) + data[1:]  # the transfer CRC's low byte
            t += 0.001
            messages.append(can.Message(timestamp=t, arbitration_id=frame.message_id, is_extended_id=True, data=data))
    return write_capture(path, messages)


def _report(capsys: pytest.CaptureFixture[str], path: Path) -> tuple[int, dict[str, Any]]:
    code = main(["can", "--format", "json", str(path)])
    return code, json.loads(capsys.readouterr().out)["captures"][0]


def test_standard_types_are_named_and_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, report = _report(capsys, _capture(tmp_path / "bus.log"))
    assert code == 0 and report["problem_counts"] == {}  # no can-unknown-type: every CRC was checked
    names = {(s["kind"], s["name"]) for s in report["streams"]}
    assert names == {
        ("message", "uavcan.protocol.NodeStatus"),
        ("response", "uavcan.protocol.GetNodeInfo"),
        ("request", "uavcan.protocol.param.GetSet"),
        ("request", "uavcan.protocol.file.Read"),
    }


def test_a_damaged_standard_transfer_is_a_crc_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, report = _report(capsys, _capture(tmp_path / "bus.log", damage=1))
    assert code == 1 and report["problem_counts"] == {"can-crc": 1}


def test_the_table_has_pydronecans_signatures() -> None:
    table = standard_types(shipped_tree())
    for name, cls in (("uavcan.protocol.GetNodeInfo", dronecan.uavcan.protocol.GetNodeInfo),
                      ("uavcan.protocol.file.Read", dronecan.uavcan.protocol.file.Read)):  # fmt: skip
        kind_id = ("request", cls.default_dtid)
        assert table[kind_id] == (name, cls.get_data_type_signature())
    ref = dronecan.uavcan.protocol.NodeStatus
    assert table[("message", ref.default_dtid)] == ("uavcan.protocol.NodeStatus", ref.get_data_type_signature())
    assert len(table) > 100  # the whole tree, not the ten battery types
