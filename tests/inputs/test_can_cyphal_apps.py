"""``battgen convert`` and ``battgen export`` of Cyphal/CAN captures whose frames pycyphal made.

Each UDRAL SourceTs transfer is one record, with its node's latest Status and Parameters beside it (as a DroneCAN
BatteryInfo takes its node's BatteryInfoAux); the values are compared with what pycyphal sent, read back by
pycyphal's own deserializer from the same transfers' payloads.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest
from test_can_cyphal import CYCLES, NODES, PARAMETERS, SOURCE, STATUS, SUBJECTS, _capture, _frames, _source, _status
from test_can_cyphal import dsdl as dsdl  # the module's fixture: nunavut's classes of the bundled types

from codegen.apps.export.query import run_query
from codegen.cli.main import main

pytest.importorskip("pycyphal")
import pycyphal.dsdl

SERIAL = {12: 0xDEADBEEF12, 13: 0xDEADBEEF13}
CAPACITY_AH = 10.0


def _parameters(d: Any, node: int) -> Any:
    charge = d["charge"].Scalar_1_0(coulomb=CAPACITY_AH * 3600.0)
    return d["battery"].Parameters_0_3(
        unique_id=SERIAL[node], design_capacity=charge, cycle_count=17, series_cell_count=6, name="pack"
    )


def _no_energy(d: Any, cycle: int) -> Any:
    """A SourceTs without its energies (NaN: unknown, as UDRAL's rule has it): the SoC is Status's charge over
    Parameters' design capacity."""
    sent = _source(d, cycle)
    sent.value.energy.joule = sent.value.full_energy.joule = math.nan
    return sent


def _bus(d: Any, starts: list[float] | None = None, source: Any = _source) -> list[tuple[int, bytes]]:
    """Each node's Parameters once, then Status and SourceTs every cycle: each SourceTs has both companions.
    ``starts``: given, gets each SourceTs transfer's time (its start frame's; the capture has one frame a ms)."""
    frames: list[tuple[int, bytes]] = []
    for node in NODES:
        frames += _frames(_parameters(d, node), PARAMETERS, node, 0, 7)
    for cycle in range(CYCLES):
        for node, cell in NODES.items():
            frames += _frames(_status(d, cell, cycle), STATUS, node, cycle, 7)
            if starts is not None:
                starts.append(0.001 * len(frames))
            frames += _frames(source(d, cycle), SOURCE, node, cycle, 7)
    return frames


def _read_back(d: Any, obj: Any) -> Any:
    """What pycyphal reads of the bytes it wrote: the values a receiver sees (float32, not the floats given)."""
    return pycyphal.dsdl.deserialize(type(obj), [memoryview(bytes(b)) for b in pycyphal.dsdl.serialize(obj)])


def test_convert_udral_capture_to_uorb_with_each_node_s_status_and_parameters(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    starts: list[float] = []
    path = _capture(tmp_path / "bus.log", _bus(dsdl, starts))
    code = main(["convert", "--from", "udral", "--to", "uorb", *SUBJECTS, str(path)])
    records = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert code == 0 and len(records) == CYCLES * len(NODES)
    for i, got in enumerate(records):  # the capture's order: each cycle, every node
        cycle, node = divmod(i, len(NODES))
        node = list(NODES)[node]
        source = _read_back(dsdl, _source(dsdl, cycle)).value
        status = _read_back(dsdl, _status(dsdl, NODES[node], cycle))
        parameters = _read_back(dsdl, _parameters(dsdl, node))
        assert got["voltage_v"] == pytest.approx(source.power.voltage.volt)
        assert got["current_a"] == -source.power.current.ampere  # UDRAL's discharge is negative, uORB's positive
        assert got["remaining"] == pytest.approx(source.energy.joule / source.full_energy.joule, rel=1e-6)
        assert got["remaining_capacity_wh"] == pytest.approx(source.energy.joule / 3600.0, rel=1e-6)
        assert got["temperature"] == pytest.approx(status.temperature_min_max[1].kelvin - 273.15, abs=1e-4)
        cells = got["voltage_cell_v"][: len(status.cell_voltages)]
        assert cells == pytest.approx([float(v) for v in status.cell_voltages])
        assert got["cell_count"] == parameters.series_cell_count and got["cycle_count"] == parameters.cycle_count
        assert math.isclose(got["timestamp"] / 1e6, starts[i], abs_tol=1e-6)  # s since the capture's first frame


def test_convert_without_the_source_subject_is_one_line(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["convert", "--from", "udral", "--to", "uorb", f"--cyphal-subject={STATUS}=status", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "expected --cyphal-subject ID=reg.udral.physics.electricity.SourceTs.0.1" in err


def test_export_udral_capture_rows_per_node_with_pycyphal_values(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    starts: list[float] = []
    path = _capture(tmp_path / "bus.log", _bus(dsdl, starts))
    out = tmp_path / "ds"
    code = main(["export", "-q", "--raw", "-o", str(out), *SUBJECTS, str(path)])
    assert code == 0, capsys.readouterr().err
    result = run_query(out, "SELECT * FROM battery ORDER BY t")
    rows = [dict(zip(result.columns, row, strict=True)) for row in result.rows]
    assert len(rows) == CYCLES * len(NODES)
    for i, row in enumerate(rows):
        cycle, node = divmod(i, len(NODES))
        node = list(NODES)[node]
        source = _read_back(dsdl, _source(dsdl, cycle)).value
        status = _read_back(dsdl, _status(dsdl, NODES[node], cycle))
        parameters = _read_back(dsdl, _parameters(dsdl, node))
        assert row["message"] == "cyphal.reg.udral.physics.electricity.SourceTs_0_1"
        assert row["battery"] == node  # UDRAL has no battery index: the node's id
        assert row["t"] == pytest.approx(starts[i], abs=1e-6)  # the capture's clock: a transfer's start frame
        assert row["time"].timestamp() == pytest.approx(1_700_000_000.0 + starts[i], abs=2e-5)
        assert row["pack_voltage"] == pytest.approx(source.power.voltage.volt)
        assert row["current"] == -source.power.current.ampere  # the concept counts a discharge as positive
        assert row["remaining_energy"] == pytest.approx(source.energy.joule)
        assert row["state_of_charge"] == pytest.approx(source.energy.joule / source.full_energy.joule, rel=1e-6)
        assert row["temperature"] == pytest.approx(status.temperature_min_max[1].kelvin)
        assert row["cell_voltages"] == pytest.approx([float(v) for v in status.cell_voltages])
        assert row["serial_number"] == parameters.unique_id and row["cycle_count"] == parameters.cycle_count
        assert row["design_capacity"] == pytest.approx(parameters.design_capacity.coulomb)
    # --raw: SourceTs's own table, the numbers inside its Scalars by their paths, as pycyphal reads them
    (raw,) = (out / "raw" / "cyphal.reg.udral.physics.electricity.SourceTs_0_1").glob("*/*.parquet")
    table = pq.read_table(raw).sort_by([("instance", "ascending"), ("t", "ascending")])
    sent = [_read_back(dsdl, _source(dsdl, cycle)).value for cycle in range(CYCLES)] * len(NODES)
    assert table["instance"].to_pylist() == [n for n in NODES for _ in range(CYCLES)]
    assert table["value.power.voltage.volt"].to_pylist() == [float(s.power.voltage.volt) for s in sent]
    assert table["value.energy.joule"].to_pylist() == [float(s.energy.joule) for s in sent]
    assert table.schema.field("value.power.current.ampere").metadata == {b"unit": b"A", b"invalid": b"NaN"}


def test_soc_from_status_and_parameters_where_the_source_has_no_energy(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """UDRAL (Status.0.2): the SoC "can be derived by dividing this value by the nominal battery capacity reported
    in the Parameters message"; convert and export agree on it."""
    path = _capture(tmp_path / "bus.log", _bus(dsdl, source=_no_energy))
    assert main(["convert", "--from", "udral", "--to", "uorb", *SUBJECTS, str(path)]) == 0
    converted = [json.loads(line)["remaining"] for line in capsys.readouterr().out.splitlines()]
    assert main(["export", "-q", "-o", str(tmp_path / "ds"), *SUBJECTS, str(path)]) == 0
    exported = [r[0] for r in run_query(tmp_path / "ds", "SELECT state_of_charge FROM battery ORDER BY t").rows]
    expected = []
    for cycle in range(CYCLES):
        for node, cell in NODES.items():
            charge = _read_back(dsdl, _status(dsdl, cell, cycle)).available_charge.coulomb
            expected.append(charge / _read_back(dsdl, _parameters(dsdl, node)).design_capacity.coulomb)
    assert converted == pytest.approx(expected, rel=1e-6) and exported == pytest.approx(expected, rel=1e-6)


def test_export_without_subjects_says_how_to_read_cyphal(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["export", "-q", "-o", str(tmp_path / "ds"), str(path)])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert f"{path}: no battery records; its start frames are Cyphal/CAN's" in err and "--cyphal-subject" in err


def test_a_large_udral_capture_read_twice_gives_the_batches_of_one_read(
    dsdl: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A capture past the streaming size is read in chunks: the same UDRAL concepts as one read."""
    from codegen.apps.battery import can_batches as can
    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.sources import model_of

    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    subjects = [s.partition("=")[2] for s in SUBJECTS]
    catalog = bundled_catalog()
    once = list(can.can_batches(path, path.name, catalog, model_of, subjects))
    monkeypatch.setattr(can, "STREAM_ABOVE", 0)
    monkeypatch.setattr(can, "CHUNK", 2)
    twice = list(can.can_batches(path, path.name, catalog, model_of, subjects))
    assert [b.instance[0] for b in once] == list(NODES) and all(b.n <= 2 for b in twice)
    for whole in once:
        parts = [b for b in twice if b.instance[0] == whole.instance[0]]
        assert whole.concepts is not None
        for name, column in whole.concepts.items():
            joined = np.concatenate([p.concepts[name].values for p in parts if p.concepts is not None])
            np.testing.assert_array_equal(joined, column.values, err_msg=name)


def test_export_in_worker_processes_takes_the_subjects(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--jobs: the subjects travel to the worker processes with the export's options."""
    first = _capture(tmp_path / "a.log", _bus(dsdl))
    second = _capture(tmp_path / "b.log", _bus(dsdl, source=_no_energy))
    out = tmp_path / "ds"
    code = main(["export", "-q", "--jobs", "2", "-o", str(out), *SUBJECTS, str(first), str(second)])
    assert code == 0, capsys.readouterr().err
    rows = run_query(out, "SELECT source, count(*) FROM battery GROUP BY source ORDER BY source").rows
    assert rows == [("a.log", CYCLES * len(NODES)), ("b.log", CYCLES * len(NODES))]
