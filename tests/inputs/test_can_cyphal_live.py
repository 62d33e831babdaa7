"""``battgen can --bus`` on a live Cyphal/CAN bus: python-can's in-process virtual bus carrying pycyphal's frames.

A UDRAL battery (Status and SourceTs, each cut into frames by pycyphal's Cyphal/CAN serializer) is sent on the
virtual bus while battgen listens, as the DroneCAN live test does with a pydronecan node. The sender keeps sending
until the command has returned, so a loaded machine changes how many transfers are seen, never whether they are
right; the reader may join and stop in the middle of a transfer, the only transport problems allowed.
"""

from __future__ import annotations

import json
import threading
import time
from typing import Any

import pytest
from test_can_cyphal import NODES, SOURCE, STATUS, SUBJECTS, _frames, _source, _status
from test_can_cyphal import dsdl as dsdl  # the module's fixture: nunavut's classes of the bundled types
from test_can_cyphal_apps import _read_back

from codegen.cli.main import main

can = pytest.importorskip("can")
pytest.importorskip("pycyphal")
NODE = next(iter(NODES))


def test_live_virtual_bus_with_pycyphal_frames(dsdl: Any, capsys: pytest.CaptureFixture[str]) -> None:
    channel = f"battgen-cyphal-{time.monotonic_ns()}"
    stop = threading.Event()
    cycle = [(STATUS, _status(dsdl, NODES[NODE], 0)), (SOURCE, _source(dsdl, 0))]

    def publish() -> None:
        bus = can.Bus(interface="virtual", channel=channel)
        try:
            deadline = time.monotonic() + 60  # bounded even if the reader never returns
            tid = 0
            while not stop.is_set() and time.monotonic() < deadline:
                for subject, obj in cycle:
                    for identifier, data in _frames(obj, subject, NODE, tid % 32, 7):
                        bus.send(can.Message(arbitration_id=identifier, is_extended_id=True, data=data))
                tid += 1
                time.sleep(0.02)
        finally:
            bus.shutdown()

    thread = threading.Thread(target=publish, daemon=True)
    thread.start()
    try:
        code = main(
            ["can", "--bus", f"virtual:{channel}", "--duration", "2.5", "--records", "--format", "json", *SUBJECTS]
        )
    finally:
        stop.set()
        thread.join(timeout=10)
    lines = capsys.readouterr().out.splitlines()
    records = [json.loads(x) for x in lines if x.startswith('{"t"')]
    report = json.loads("\n".join(x for x in lines if not x.startswith('{"t"')))["captures"][0]
    sources = [r for r in records if r.get("subject") == SOURCE]
    assert len(sources) >= 3
    sent = _read_back(dsdl, _source(dsdl, 0)).value
    for r in sources:
        value = r["message"]["value"]
        assert r["node"] == NODE and r["protocol"] == "cyphal"
        assert value["power"]["voltage"]["volt"] == pytest.approx(sent.power.voltage.volt)
        assert value["energy"]["joule"] == pytest.approx(sent.energy.joule)
    statuses = [r for r in records if r.get("subject") == STATUS]
    assert statuses and all(r["message"]["cell_voltages"] == pytest.approx([3.7] * 6, abs=1e-3) for r in statuses)
    counts = report["problem_counts"]
    assert set(counts) <= {"can-missing-start", "can-missing-end"} and all(n <= 2 for n in counts.values()), counts
    assert code == (1 if counts else 0)
