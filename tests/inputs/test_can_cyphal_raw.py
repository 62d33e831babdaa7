"""``battgen export --raw`` of a Cyphal/CAN capture: each type ``--cyphal-subject`` names is its own table.

The capture holds UDRAL's battery service (SourceTs, Status, Parameters) and the physics types PowerTs and Source on
subjects of their own, every transfer made by pycyphal; each table's rows must equal pycyphal's own decode of the
same transfers, column by column (a composite's numbers by their dotted paths).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest
from test_can_cyphal import CYCLES, NODES, PARAMETERS, SOURCE, STATUS, SUBJECTS, _capture, _frames, _status
from test_can_cyphal import dsdl as dsdl  # the module's fixture: nunavut's classes of the bundled types
from test_can_cyphal_apps import _parameters, _read_back, _source

from codegen.apps.export.cyphal_raw import number_paths
from codegen.apps.schemas.package import load_schemas
from codegen.cli.main import main

pytest.importorskip("pycyphal")
POWER_TS, PLAIN_SOURCE = 4099, 4100
RAW_SUBJECTS = [
    *SUBJECTS,
    f"--cyphal-subject={POWER_TS}=reg.udral.physics.electricity.PowerTs.0.1",
    f"--cyphal-subject={PLAIN_SOURCE}=reg.udral.physics.electricity.Source",
]
PREFIX = "cyphal.reg.udral."
TABLES = {  # subject -> (our qualified name, what each node sent on it each cycle)
    STATUS: (PREFIX + "service.battery.Status_0_2", lambda d, node, cycle: _status(d, NODES[node], cycle)),
    SOURCE: (PREFIX + "physics.electricity.SourceTs_0_1", lambda d, node, cycle: _source(d, cycle)),
    PARAMETERS: (PREFIX + "service.battery.Parameters_0_3", lambda d, node, cycle: _parameters(d, node)),
    POWER_TS: (PREFIX + "physics.electricity.PowerTs_0_1", lambda d, node, cycle: _source(d, cycle + node)),
    PLAIN_SOURCE: (PREFIX + "physics.electricity.Source_0_1", lambda d, node, cycle: _source(d, cycle).value),
}


def _sent(d: Any, subject: int, node: int, cycle: int) -> Any:
    obj = TABLES[subject][1](d, node, cycle)
    if subject == POWER_TS:  # a PowerTs of the SourceTs's power, with a timestamp of its own
        electricity = d["electricity"]
        stamp = type(obj.timestamp)(microsecond=1000 * cycle + node)
        return electricity.PowerTs_0_1(timestamp=stamp, value=obj.value.power)
    return obj


def _bus(d: Any) -> list[tuple[int, bytes]]:
    frames: list[tuple[int, bytes]] = []
    for cycle in range(CYCLES):
        for node in NODES:
            for subject in TABLES:
                frames += _frames(_sent(d, subject, node, cycle), subject, node, cycle, 7)
    return frames


def _value(obj: Any, path: str) -> Any:
    """The value at a dotted path of a pycyphal object (an attribute, or an index into an array)."""
    for step in path.split("."):
        obj = obj[int(step)] if step.isdigit() else getattr(obj, step)
    return obj


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [v.item() for v in value]
    return value.item() if isinstance(value, np.generic) else value


def _nan_named(value: Any) -> Any:
    """NaN as a word, so that equal lists with NaN in them compare equal."""
    if isinstance(value, list):
        return [_nan_named(v) for v in value]
    return "NaN" if isinstance(value, float) and value != value else value


def test_export_raw_writes_every_subject_type_as_pycyphal_decodes_it(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    out = tmp_path / "ds"
    code = main(["export", "-q", "--raw", "-o", str(out), *RAW_SUBJECTS, str(path)])
    assert code == 0, capsys.readouterr().err
    schema = load_schemas(Path(__file__).resolve().parents[2] / "schemas")
    for subject, (qualified, _) in TABLES.items():
        (file,) = (out / "raw" / qualified).glob("*/*.parquet")
        table = pq.read_table(file).sort_by([("instance", "ascending"), ("t", "ascending")])
        assert table["instance"].to_pylist() == [n for n in NODES for _ in range(CYCLES)], qualified
        message = schema.message(qualified)
        paths = list(number_paths(message, schema))
        plain = [f.name for f in message.fields if f.name and not any(p.startswith(f.name + ".") for p in paths)]
        for name in plain:
            paths.append(name)
        assert paths and set(paths) <= set(table.column_names), (qualified, set(paths) - set(table.column_names))
        expected = [_read_back(dsdl, _sent(dsdl, subject, n, c)) for n in NODES for c in range(CYCLES)]
        for column in paths:
            got = table[column].to_pylist()
            want = [_plain(_value(e, column)) for e in expected]
            assert _nan_named(got) == _nan_named(want), (qualified, column)  # equal, bit for bit
    energy = pq.read_table(next((out / "raw" / TABLES[SOURCE][0]).glob("*/*.parquet")))
    assert energy.schema.field("value.power.current.ampere").metadata == {b"unit": b"A", b"invalid": b"NaN"}
    parameters = pq.read_table(next((out / "raw" / TABLES[PARAMETERS][0]).glob("*/*.parquet")))
    assert bytes(parameters["name"][0].as_py()) == b"pack"  # uint8[<=64], as UDRAL declares it: its bytes
    status = pq.read_table(next((out / "raw" / TABLES[STATUS][0]).glob("*/*.parquet")))
    assert status.schema.field("temperature_min_max.1.kelvin").metadata[b"unit"] == b"K"


def test_a_mixed_bus_keeps_its_dronecan_raw_table_beside_the_cyphal_ones(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """DroneCAN BatteryInfo (made by pydronecan) on the same bus as the UDRAL battery: --raw writes both."""
    dronecan = pytest.importorskip("dronecan")
    frames = _bus(dsdl)
    for cycle in range(CYCLES):
        info = dronecan.uavcan.equipment.power.BatteryInfo(voltage=23.5, battery_id=3)
        transfer = dronecan.transport.Transfer(transfer_id=cycle, source_node_id=30, payload=info, transfer_priority=20)
        frames += [(frame.message_id, bytes(frame.bytes)) for frame in transfer.to_frames()]
    path = _capture(tmp_path / "bus.log", frames)
    out = tmp_path / "ds"
    assert main(["export", "-q", "--raw", "-o", str(out), *RAW_SUBJECTS, str(path)]) == 0, capsys.readouterr().err
    (file,) = (out / "raw" / "dronecan.uavcan.equipment.power.BatteryInfo").glob("*/*.parquet")
    assert pq.read_table(file)["voltage"].to_pylist() == [23.5] * CYCLES
    for qualified, _ in TABLES.values():
        (file,) = (out / "raw" / qualified).glob("*/*.parquet")
        assert pq.read_table(file).num_rows == CYCLES * len(NODES)
