"""``battgen can --schemas DIR``: Cyphal's standard types with fixed port ids, read from a user's DSDL tree.

The tree is upstream's public_regulated_data_types (../shared/corpus/cyphal/). pycyphal compiles its ``uavcan``
namespace and makes the transfers (a Heartbeat on its fixed subject 7509, a port List on 7510, which takes several
frames and so a transfer CRC), cut into frames by pycyphal's Cyphal/CAN serializer beside a UDRAL battery; battgen
must name and decode them with the values pycyphal sent, where without the tree they are unknown subjects.
"""

from __future__ import annotations

import importlib
import json
import sys
from pathlib import Path
from typing import Any

import pytest
from shared_data import shared
from test_can_cyphal import STATUS, SUBJECTS, _capture, _frames, _status
from test_can_cyphal import dsdl as dsdl  # the module's fixture: nunavut's classes of the bundled types

from codegen.cli.main import main

pytest.importorskip("pycyphal")
import pycyphal.dsdl

CORPUS = shared("corpus", "cyphal")
pytestmark = pytest.mark.skipif(not (CORPUS / "uavcan").is_dir(), reason="the Cyphal corpus is not present")
HEARTBEAT, PORT_LIST = 7509, 7510  # uavcan.node.Heartbeat.1.0 and uavcan.node.port.List.1.0: their fixed ids
NODE = 21


@pytest.fixture(scope="module")
def standard(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """pycyphal's classes of the corpus's uavcan namespace."""
    out = tmp_path_factory.mktemp("uavcan")
    pycyphal.dsdl.compile(CORPUS / "uavcan", output_directory=out)
    # the bundled types' fixture imported its own (smaller) uavcan package: set it aside while this one is imported
    aside = {name: sys.modules.pop(name) for name in list(sys.modules) if name.split(".")[0] == "uavcan"}
    sys.path.insert(0, str(out))
    try:
        node = importlib.import_module("uavcan.node")
        port = importlib.import_module("uavcan.node.port")
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] == "uavcan"]:
            del sys.modules[name]
        sys.modules.update(aside)
    return {"node": node, "port": port}


def _heartbeat(s: Any, k: int) -> Any:
    node = s["node"]
    return node.Heartbeat_1_0(
        uptime=1000 + k,
        health=node.Health_1_0(value=k % 4),
        mode=node.Mode_1_0(value=k % 3),
        vendor_specific_status_code=7 * k,
    )


def _port_list(s: Any) -> Any:
    return s["port"].List_1_0()  # the empty sets: longer than one classic frame


def _bus(d: Any, s: Any) -> list[tuple[int, bytes]]:
    frames: list[tuple[int, bytes]] = []
    for k in range(3):
        frames += _frames(_heartbeat(s, k), HEARTBEAT, NODE, k, 7)
        frames += _frames(_status(d, 3.7, k), STATUS, NODE, k, 7)
    frames += _frames(_port_list(s), PORT_LIST, NODE, 0, 7)
    return frames


def _read_back(obj: Any) -> Any:
    return pycyphal.dsdl.deserialize(type(obj), [memoryview(bytes(b)) for b in pycyphal.dsdl.serialize(obj)])


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[dict[str, Any]], dict[str, Any]]:
    code = main(["can", "--records", "--format", "json", *args])
    lines = capsys.readouterr().out.splitlines()
    records = [json.loads(x) for x in lines if x.startswith('{"t"')]
    report = json.loads("\n".join(x for x in lines if not x.startswith('{"t"')))["captures"][0]
    return code, records, report


def test_standard_types_from_the_user_s_tree_are_named_and_decoded(
    dsdl: Any, standard: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert len(_frames(_port_list(standard), PORT_LIST, NODE, 0, 7)) > 1  # a multi-frame transfer: CRC-checked
    path = _capture(tmp_path / "bus.log", _bus(dsdl, standard))
    code, records, report = _run(capsys, "--schemas", str(CORPUS), *SUBJECTS, str(path))
    assert code == 0 and report["problem_counts"] == {}
    streams = {s["data_type_id"]: s for s in report["streams"]}
    assert streams[HEARTBEAT]["name"] == "uavcan.node.Heartbeat.1.0" and streams[HEARTBEAT]["count"] == 3
    assert streams[PORT_LIST]["name"] == "uavcan.node.port.List.1.0" and streams[PORT_LIST]["count"] == 1
    assert streams[STATUS]["name"] == "reg.udral.service.battery.Status.0.2"  # --cyphal-subject still read
    beats = [r for r in records if r.get("subject") == HEARTBEAT]
    assert [r["node"] for r in beats] == [NODE] * 3
    for k, got in enumerate(beats):
        sent = _read_back(_heartbeat(standard, k))
        message = got["message"]
        assert message["uptime"] == sent.uptime
        assert message["health"]["value"] == sent.health.value and message["mode"]["value"] == sent.mode.value
        assert message["vendor_specific_status_code"] == sent.vendor_specific_status_code
    (listed,) = [r for r in records if r.get("subject") == PORT_LIST]
    assert listed["type"] == "List_1_0" and listed["node"] == NODE


def test_without_the_tree_they_are_unknown_subjects(
    dsdl: Any, standard: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl, standard))
    code, records, report = _run(capsys, *SUBJECTS, str(path))
    streams = {s["data_type_id"]: s for s in report["streams"]}
    assert code == 0 and streams[HEARTBEAT]["name"] == "" and streams[PORT_LIST]["name"] == ""
    assert not [r for r in records if r.get("subject") in (HEARTBEAT, PORT_LIST)]


def test_a_folder_without_definitions_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bus.log"
    path.write_text("(1700000000.000000) can0 1C7D5015#0000000000000000E0\n")
    for folder in (tmp_path / "missing", tmp_path / "empty"):
        if folder.name == "empty":
            folder.mkdir()
        code = main(["can", "--schemas", str(folder), str(path)])
        err = capsys.readouterr().err
        assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
