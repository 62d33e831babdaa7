"""battgen export on CAN captures: DroneCAN BatteryInfo (+ BatteryInfoAux) and CUAV CBAT, every node
a battery. The frames are made by pydronecan's transport from its own message objects and written by
python-can's log writers; each row is checked against pydronecan's decode of the same frames, in the
units the DSDL comments and PX4's bridge give (CBAT: a discharge negative, percentages)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from codegen.apps.export.query import run_query
from codegen.cli.main import main

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")
from dronecan import transport  # noqa: E402

START = 1_700_000_000.0
CYCLES = 5
POWER = dronecan.uavcan.equipment.power
AP_POWER = dronecan.ardupilot.equipment.power
CUAV = dronecan.cuav.equipment.power


def _info(node: int, battery_id: int, k: int) -> list[Any]:
    """One node's cycle: BatteryInfoAux then BatteryInfo (PX4's order)."""
    aux = AP_POWER.BatteryInfoAux(
        voltage_cell=[3.9 - k * 0.01, 3.91, 3.92, 3.9 - k * 0.02], cycle_count=12 + node, battery_id=battery_id
    )
    info = POWER.BatteryInfo(
        voltage=15.6 - 0.05 * k,
        current=5.5 + k,
        temperature=300.0 + k,
        battery_id=battery_id,
        model_instance_id=1000 + node,
        model_name="pack 4S",
        state_of_charge_pct=90 - k,
    )
    return [aux, info]


def _cbat(k: int) -> Any:
    return CUAV.CBAT(
        voltage=23.1 - 0.1 * k,
        current=-12.5 - k,  # CBAT reports a discharge as negative
        temperature=298.15,
        voltage_cell=[3.85, 3.86, 3.85, 3.84, 3.85, 3.86],
        cell_count=6,
        state_of_charge=70 - k,
        state_of_health=96,
        cycle_count=33,
        serial_number=4242,
        full_charge_capacity=16000,
    )


def _capture(path: Path, nodes: dict[int, int], cbat_node: int | None = None, damage: int | None = None) -> Any:
    """Write the capture; return pydronecan's decode of each transfer as (node, message, time of its first
    frame since the capture's first frame) in bus order."""
    decoded: list[tuple[int, Any, float]] = []
    writer = can.Logger(str(path))
    t = START
    count = 0
    try:
        for k in range(CYCLES):
            payloads = [(node, m) for node, bid in nodes.items() for m in _info(node, bid, k)]
            if cbat_node is not None:
                payloads.append((cbat_node, _cbat(k)))
            for node, payload in payloads:
                tr = transport.Transfer(transfer_id=k, source_node_id=node, payload=payload, transfer_priority=20)
                frames = tr.to_frames()
                back = transport.Transfer()
                back.from_frames([transport.Frame(f.message_id, f.bytes) for f in frames])
                count += 1
                for j, frame in enumerate(frames):
                    data = bytes(frame.bytes)
                    if damage == count and j == 0:  # the low byte of the transfer CRC
                        data = bytes([data[0] ^ 0x5A]) + data[1:]
                    t += 0.001
                    writer.on_message_received(
                        can.Message(timestamp=t, arbitration_id=frame.message_id, is_extended_id=True, data=data)
                    )
                if damage != count:
                    decoded.append((node, back.payload, round(t - START - 0.001 * len(frames), 6)))
    finally:
        writer.stop()
    return decoded


def _type(message: Any) -> str:
    return str(dronecan.get_dronecan_data_type(message).full_name)


def _export(capsys: pytest.CaptureFixture[str], out: Path, *logs: Path) -> tuple[int, str]:
    code = main(["export", "-o", str(out), *map(str, logs)])
    return code, capsys.readouterr().err


def _rows(out: Path, where: str) -> list[dict[str, Any]]:
    result = run_query(out, f"SELECT * FROM battery WHERE {where} ORDER BY battery, t")
    return [dict(zip(result.columns, row, strict=True)) for row in result.rows]


@pytest.mark.parametrize("suffix", [".log", ".asc", ".blf", ".trc"])
def test_battery_info_with_aux_and_cbat_per_node(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    capture = tmp_path / f"bus{suffix}"
    decoded = _capture(capture, {10: 0, 11: 1}, cbat_node=12)
    out = tmp_path / "ds"
    code, err = _export(capsys, out, capture)
    assert code == 0, err
    infos = [(n, m) for n, m, _ in decoded if _type(m) == "uavcan.equipment.power.BatteryInfo"]
    auxes = [(n, m) for n, m, _ in decoded if _type(m) == "ardupilot.equipment.power.BatteryInfoAux"]
    rows = _rows(out, "message LIKE '%BatteryInfo'")
    assert len(rows) == len(infos) == 2 * CYCLES
    by_node = sorted(infos, key=lambda x: (x[1].battery_id, infos.index(x)))
    for row, (node, ref) in zip(rows, by_node, strict=True):
        aux = next(a for n, a in auxes if n == node and a.cycle_count == 12 + node)  # this node's aux
        assert row["battery"] == ref.battery_id
        assert row["pack_voltage"] == ref.voltage  # float16 on the wire: the same value pydronecan decodes
        assert row["current"] == ref.current
        assert row["temperature"] == ref.temperature
        assert row["state_of_charge"] == pytest.approx(ref.state_of_charge_pct / 100)
        assert row["serial_number"] == ref.model_instance_id
        assert row["cycle_count"] == aux.cycle_count
        assert row["vehicle"] is None and row["source"] == capture.name
    # the cells: each BatteryInfo with the aux its node sent just before it
    cells = [r["cell_voltages"] for r in rows if r["battery"] == 0]
    ref_cells = [list(a.voltage_cell) for n, a in auxes if n == 10]
    assert cells == [pytest.approx(c) for c in ref_cells]
    cbat_rows = _rows(out, "message LIKE '%CBAT'")
    ref_cbat = [m for n, m, _ in decoded if n == 12]
    assert len(cbat_rows) == CYCLES
    for row, ref in zip(cbat_rows, ref_cbat, strict=True):
        assert row["battery"] == 12  # CBAT carries no battery id: the node's
        assert row["pack_voltage"] == pytest.approx(ref.voltage)
        assert row["current"] == pytest.approx(-ref.current)  # positive while discharging, as PX4 reads it
        assert row["state_of_charge"] == pytest.approx(ref.state_of_charge / 100)
        assert row["state_of_health"] == pytest.approx(0.96)
        assert row["cell_voltages"] == pytest.approx(list(ref.voltage_cell))
        assert row["serial_number"] == 4242 and row["cycle_count"] == 33
        assert row["full_capacity"] == pytest.approx(16000 * 3.6)  # mAh -> C
    times = [r["t"] for r in _rows(out, "battery = 0")]  # seconds since the first frame, at a transfer's first
    assert times == pytest.approx([t for n, m, t in decoded if n == 10 and _type(m).endswith("BatteryInfo")], abs=2e-6)
    stamps = [r["time"] for r in _rows(out, "battery = 0")]
    if suffix != ".asc":  # absolute stamps: candump as logged, BLF and TRC from their header's start time
        first = START + 0.001
        assert [s.timestamp() for s in stamps] == pytest.approx([first + t for t in times], abs=2e-5)
    else:  # python-can's ASC reader counts from the start
        assert stamps == [None] * len(stamps)
    flights = run_query(out, "SELECT battery, records, pack FROM flights ORDER BY battery").rows
    assert flights == [(0, CYCLES, "1010"), (1, CYCLES, "1011"), (12, CYCLES, "4242")]


def test_nodes_sharing_a_battery_id_and_damage(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capture = tmp_path / "bus.log"
    _capture(capture, {20: 0, 21: 0}, damage=4)  # the second BatteryInfo of node 21 has a bad CRC
    out = tmp_path / "ds"
    code, err = _export(capsys, out, capture)
    assert code == 0, err
    assert run_query(out, "SELECT battery, count(*) FROM battery GROUP BY ALL ORDER BY 1").rows == [
        (20, CYCLES),
        (21, CYCLES - 1),
    ]
    notes = json.loads(next(out.glob("logs/*.json")).read_text())["notes"]
    assert "nodes 20, 21 share battery_id 0: batteries numbered by node id" in notes
    assert any(n.startswith("1 damaged or undecodable transfers skipped") for n in notes)


def test_empty_and_foreign_captures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    empty = tmp_path / "empty.log"
    empty.write_text("", encoding="utf-8")
    folder = tmp_path / "logs"
    folder.mkdir()
    (folder / "syslog.log").write_text("Dec  1 22:00:01 host cron[1]: job done\n", encoding="utf-8")
    _capture(folder / "bus.log", {10: 0})
    code, err = _export(capsys, tmp_path / "ds", empty, folder)
    assert code == 1
    assert "empty.log: no CAN frames in this capture" in err and ":0:" not in err  # no fake line 0
    assert "syslog" not in err  # a folder's .log that is no candump capture is not an input
    assert "2 logs: 1 exported" in err


def test_columnar_with_aux_equals_the_generated_converter(tmp_path: Path) -> None:
    """The export's concepts of a capture (columnar, the aux message's filled in) are the generated
    per-record converter's ``to_concepts(info, aux)`` on the same records, concept by concept."""
    from per_record import states_to_columns

    from codegen.apps.battery.can_batches import AUX, CBAT, INFO, can_batches
    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.sources import model_of
    from codegen.apps.export.table import concept_array
    from codegen.inputs.can.records import capture_side
    from codegen.inputs.records import Record
    from generated.convert import CONVERTERS

    capture = tmp_path / "bus.log"
    _capture(capture, {10: 0, 11: 3}, cbat_node=12)
    catalog = bundled_catalog()
    batches = list(can_batches(capture, capture.name, catalog, model_of))
    for qualified, endpoint in (((INFO, AUX), "dronecan"), ((CBAT,), "cbat")):
        items = capture_side(capture, capture.name, [model_of(catalog, q) for q in qualified])
        records = [i for i in items if isinstance(i, Record)]
        convert = CONVERTERS[(endpoint, "concepts")]
        for batch in (b for b in batches if b.message == qualified[0]):
            mine = [r for r in records if (r.location or {})["node"] == batch.instance[0]]
            assert batch.concepts is not None and len(mine) == batch.n
            expected = states_to_columns(catalog, [convert(r.instance, *r.companions) for r in mine])
            for concept in catalog.concepts:
                a, b = concept_array(batch.concepts[concept.name]), concept_array(expected[concept.name])
                assert a.equals(b), f"{qualified[0]} node {batch.instance[0]}: {concept.name}"
    assert sorted((b.message.rsplit(".", 1)[1], int(b.instance[0])) for b in batches) == [
        ("BatteryInfo", 10),
        ("BatteryInfo", 11),
        ("CBAT", 12),
    ]


@pytest.mark.parametrize("shared_id", [False, True])
def test_a_capture_read_twice_gives_the_batches_of_one_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, shared_id: bool
) -> None:
    """A large capture is read twice and handed out in chunks (flat memory): the same records, battery numbers
    (node ids where two nodes share a battery_id), times and notes as one read."""
    from codegen.apps.battery import can_batches as can
    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.sources import model_of

    capture = tmp_path / "bus.log"
    _capture(capture, {10: 0, 11: 0 if shared_id else 3}, cbat_node=12)
    catalog = bundled_catalog()
    once = list(can.can_batches(capture, capture.name, catalog, model_of))
    monkeypatch.setattr(can, "STREAM_ABOVE", 0)
    monkeypatch.setattr(can, "CHUNK", 2)
    twice = list(can.can_batches(capture, capture.name, catalog, model_of))
    assert all(b.n <= 2 for b in twice) and sum(b.n for b in twice) == sum(b.n for b in once)
    assert [n for b in once for n in b.notes] == [n for b in twice for n in b.notes]
    assert any("share battery_id" in n for b in once for n in b.notes) == shared_id
    for whole in once:
        parts = [b for b in twice if b.message == whole.message and b.instance[0] == whole.instance[0]]
        assert whole.concepts is not None and all(p.concepts is not None for p in parts)
        for name, column in whole.concepts.items():
            joined = np.concatenate([p.concepts[name].values for p in parts if p.concepts is not None])
            np.testing.assert_array_equal(joined, column.values, err_msg=name)
        np.testing.assert_array_equal(np.concatenate([p.t for p in parts]), whole.t)
