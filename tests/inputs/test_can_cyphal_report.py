"""``battgen report`` and ``battgen failsafe`` of Cyphal/CAN captures whose frames pycyphal made.

Both read a capture through the battery view ``export`` reads (``--cyphal-subject ID=TYPE`` naming the subjects'
types): each node's UDRAL SourceTs with its Status and Parameters. The values are compared with pycyphal's own
read-back of the transfers it made.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from can_logs import write_capture
from test_can_cyphal import CYCLES, NODES, SUBJECTS, _capture, _status
from test_can_cyphal import dsdl as dsdl  # the module's fixture: nunavut's classes of the bundled types
from test_can_cyphal_apps import _bus, _read_back, _source

from codegen.apps.failsafe.settings import prefix
from codegen.cli.main import main

pytest.importorskip("pycyphal")
can = pytest.importorskip("can")


def test_report_json_of_a_udral_capture_has_each_node_with_pycyphal_values(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["report", "--format", "json", *SUBJECTS, str(path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    (item,) = json.loads(out)["inputs"]
    assert item["records"] == CYCLES * len(NODES) and item["findings"] == 0
    assert [b["battery"] for b in item["batteries"]] == list(NODES)  # UDRAL has no battery index: the node id
    sent = [_read_back(dsdl, _source(dsdl, cycle)).value for cycle in range(CYCLES)]
    for battery in item["batteries"]:
        cell = NODES[battery["battery"]]
        status = [_read_back(dsdl, _status(dsdl, cell, cycle)) for cycle in range(CYCLES)]
        figures = battery["figures"]
        assert battery["message"] == "cyphal.reg.udral.physics.electricity.SourceTs_0_1"
        assert battery["label"] == f"node {battery['battery']}"
        assert figures["min_pack_voltage_v"] == pytest.approx(min(s.power.voltage.volt for s in sent))
        assert figures["peak_current_a"] == pytest.approx(-sent[0].power.current.ampere)  # discharge positive
        assert figures["min_cell_voltage_v"] == pytest.approx(min(float(v) for s in status for v in s.cell_voltages))
        hottest = max(s.temperature_min_max[1].kelvin for s in status)
        assert figures["max_temperature_c"] == pytest.approx(hottest - 273.15, abs=1e-4)


def test_report_of_a_udral_capture_without_subjects_reads_no_battery(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["report", "-o", str(tmp_path / "r.html"), str(path)])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err and "--cyphal-subject" in err
    assert not (tmp_path / "r.html").exists()


def test_report_with_a_wrong_subject_pair_is_one_line(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["report", "--cyphal-subject", "4096=no.such.Type", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1 and "no.such.Type" in err


def test_failsafe_replays_a_udral_capture_s_batteries(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ArduPilot's failsafe over the capture's UDRAL packs (a frame a second): a low-voltage threshold above the
    packs' voltage fires on each node's battery once BATT_LOW_TIMER has passed (no arming state: taken as armed)."""
    frames = _bus(dsdl)
    messages = [
        can.Message(timestamp=1_700_000_000.0 + i, arbitration_id=i_d, is_extended_id=True, data=data)
        for i, (i_d, data) in enumerate(frames)
    ]
    path = write_capture(tmp_path / "bus.log", messages)
    volts = _read_back(dsdl, _source(dsdl, 0)).value.power.voltage.volt
    params = tmp_path / "batt.param"
    # a UDRAL battery is numbered by its node: node 12 is ArduPilot's battery 13, whose parameters are BATTD_
    heads = [prefix(node + 1) for node in NODES]
    params.write_text("".join(f"{h}MONITOR,8\n{h}LOW_VOLT,{volts + 1:.1f}\n{h}LOW_TIMER,1\n" for h in heads))
    code = main(["failsafe", "--json", "--params", str(params), "--vehicle", "copter", *SUBJECTS, str(path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    events = [json.loads(x) for x in out.splitlines()]
    assert f"{CYCLES * len(NODES)} samples" in err and "taken as armed" in err
    assert sorted(e["battery"] for e in events) == sorted(n + 1 for n in NODES), events
    for e in events:
        assert e["level"] == "LOW" and e["cause"] == "voltage" and e["value"] == pytest.approx(volts), e
        assert "cyphal.reg.udral.physics.electricity.SourceTs_0_1" in e["where"]


def test_failsafe_without_subjects_says_how_to_read_cyphal(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    params = tmp_path / "batt.param"
    params.write_text("BATT_MONITOR,8\nBATT_LOW_VOLT,30\n")
    code = main(["failsafe", "--params", str(params), str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and "--cyphal-subject" in err


def test_convert_a_capture_from_nxp_s_bms_reads_its_temperatures_with_272_15(
    dsdl: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--sender nxp-bms772 on decoded transfers (not only JSON records): the hottest sensor pycyphal sent, less
    NXP's 272.15 (NXP rddrone-bms772, src/uavcan.c: CELSIUS_TO_KELVIN), is the °C written."""
    path = _capture(tmp_path / "bus.log", _bus(dsdl))
    code = main(["convert", "--from", "udral", "--to", "uorb", "--sender", "nxp-bms772", *SUBJECTS, str(path)])
    records = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert code == 0 and len(records) == CYCLES * len(NODES)
    for i, got in enumerate(records):
        cycle, node = divmod(i, len(NODES))
        status = _read_back(dsdl, _status(dsdl, NODES[list(NODES)[node]], cycle))
        assert got["temperature"] == pytest.approx(status.temperature_min_max[1].kelvin - 272.15, abs=1e-4)
