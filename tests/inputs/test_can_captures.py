"""CAN captures as users have them: every capture format, DataFlash CANF records, a live bus, damaged input.

The frames are made by pydronecan's transport (its ``Transfer.to_frames``) and written by python-can's own log
writers (candump, ASC, BLF, TRC, CSV), so the files are what those tools record; a DataFlash log is written with
the FMT/CANF records ArduPilot's ``AP_CANManager/LogStructure.h`` declares, and read by pymavlink.
"""

from __future__ import annotations

import gzip
import json
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from can_logs import write_capture
from dataflash_writer import DataflashWriter

from codegen.cli.main import main
from codegen.inputs.can.captures import read_capture
from codegen.inputs.records import InputError

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")
from dronecan import transport  # noqa: E402

NODES = (10, 11)
CYCLES = 4


def _messages(*, aux_after: bool = False, corrupt_transfer: int | None = None) -> list[Any]:
    """BatteryInfoAux then BatteryInfo from each node, CYCLES times, as python-can messages (10 ms apart)."""
    out: list[Any] = []
    t = 1_700_000_000.0
    transfers = 0
    for cycle in range(CYCLES):
        for node in NODES:
            aux = dronecan.ardupilot.equipment.power.BatteryInfoAux(
                voltage_cell=[3.9, 3.91, 3.92, 3.9, 3.88, 3.9], cycle_count=12, battery_id=node
            )
            info = dronecan.uavcan.equipment.power.BatteryInfo(
                voltage=23.4,
                current=5.5,
                temperature=300.0,
                battery_id=node,
                model_name="pack 6S",
                state_of_charge_pct=80,
            )
            order = (info, aux) if aux_after and node == NODES[1] else (aux, info)
            for payload in order:
                tr = transport.Transfer(transfer_id=cycle, source_node_id=node, payload=payload, transfer_priority=20)
                transfers += 1
                for k, frame in enumerate(tr.to_frames()):
                    data = bytes(frame.bytes)
                    if corrupt_transfer == transfers and k == 0:  # the low byte of the transfer CRC
                        data = bytes([data[0] ^ 0x5A]) + data[1:]
                    t += 0.0005
                    out.append(
                        can.Message(
                            timestamp=t, arbitration_id=frame.message_id, is_extended_id=True, data=data, channel="can0"
                        )
                    )
    return out


WRITERS = {".log": "CanutilsLogWriter", ".asc": "ASCWriter", ".blf": "BLFWriter", ".trc": "TRCWriter"}


_write = write_capture


def _validate(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict[str, Any], str]:
    code = main(["validate", "--format", "json", *args])
    out, err = capsys.readouterr()
    return code, json.loads(out), err


@pytest.mark.parametrize("suffix", [".log", ".asc", ".blf", ".trc", ".log.gz"])
def test_every_capture_format_gives_each_nodes_records(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    path = _write(tmp_path / f"bus{suffix}", _messages())
    code, doc, _ = _validate(capsys, str(path))
    assert code == 0, doc
    report = doc["files"][0]
    assert doc["message"] == "dronecan.uavcan.equipment.power.BatteryInfo"
    assert report["records"] == CYCLES * len(NODES)
    summary = next(n for n in report["notices"] if n["kind"] == "stream")
    assert summary["data"]["nodes"] == {str(n): CYCLES for n in NODES}


def test_csv_capture_read_when_asked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path / "bus.csv", _messages())
    code, doc, _ = _validate(capsys, "--input-format", "can", str(path))
    assert code == 0 and doc["files"][0]["records"] == CYCLES * len(NODES)


def _dataflash(path: Path, messages: list[Any]) -> Path:
    """An ArduPilot DataFlash log holding FMT and CANF records (layout of AP_CANManager/LogStructure.h)."""
    log = DataflashWriter()
    columns = ("TimeUS", "Bus", "Id", "DLC", "B0", "B1", "B2", "B3", "B4", "B5", "B6", "B7")
    log.define("CANF", "QBIBBBBBBBBB", columns, type_id=200)
    t0 = messages[0].timestamp
    for m in messages:
        data = bytes(m.data) + bytes(8 - len(m.data))
        raw_id = m.arbitration_id | (1 << 31)  # AP_HAL::CANFrame::FlagEFF: an extended frame
        log.write("CANF", int((m.timestamp - t0) * 1e6) + 1000, 0, raw_id, len(m.data), *data)
    return log.save(path)


def test_dataflash_canf_records(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _dataflash(tmp_path / "00000042.BIN", _messages())
    code, doc, _ = _validate(capsys, "--message", "dronecan.uavcan.equipment.power.BatteryInfo", str(path))
    assert code == 0, doc
    assert doc["files"][0]["records"] == CYCLES * len(NODES)


def test_damaged_capture_reports_the_frame_and_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    messages = _messages(corrupt_transfer=4)  # node 11's first BatteryInfo
    first = next(i for i, m in enumerate(messages) if m.data[0] != _messages()[i].data[0])
    path = _write(tmp_path / "bad.log", messages)
    code = main(["validate", str(path)])
    _, err = capsys.readouterr()
    assert code == 1
    line = next(x for x in err.splitlines() if "[can-crc]" in x)
    assert f"frame {first}:" in line and "t=" in line and "node 11" in line and "expected 0x" in line


def test_aux_after_battery_info_is_a_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path / "late.log", _messages(aux_after=True))
    code = main(["validate", str(path)])
    _, err = capsys.readouterr()
    assert code == 0  # a warning: the data is fine, its order is not
    late = [x for x in err.splitlines() if "[can-aux-order]" in x]
    assert late and all("node 11" in x for x in late)


def test_can_command_counts_nodes_and_rates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path / "bus.log", _messages())
    code = main(["can", "--format", "json", str(path)])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    streams = {(s["node"], s["name"]): s for s in doc["captures"][0]["streams"]}
    assert set(streams) == {
        (n, name)
        for n in NODES
        for name in ("uavcan.equipment.power.BatteryInfo", "ardupilot.equipment.power.BatteryInfoAux")
    }
    assert all(s["count"] == CYCLES and s["rate_hz"] > 0 for s in streams.values())


def test_convert_pairs_each_battery_info_with_its_nodes_aux(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path / "bus.log", _messages())
    code = main(["convert", "--from", "dronecan", "--to", "uorb", str(path)])
    rows = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert code == 0 and len(rows) == CYCLES * len(NODES)
    for row in rows:
        assert row["cell_count"] == 6 and row["cycle_count"] == 12
        assert [round(v, 2) for v in row["voltage_cell_v"][:6]] == [3.9, 3.91, 3.92, 3.9, 3.88, 3.9]


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (b"", "no CAN frames"),
        (b"\x00\xff" * 300, "junk.log:1: expected a candump -l line"),
        (b"(1.0) can0 ZZZ#GG\n", "junk.log:1: expected a candump -l line"),
    ],
)
def test_unreadable_or_empty_capture_is_one_clear_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes, expected: str
) -> None:
    path = tmp_path / "junk.log"
    path.write_bytes(content)
    code = main(["validate", str(path)])
    _, err = capsys.readouterr()
    assert code != 0 and "Traceback" not in err
    assert expected in err


def test_live_virtual_bus_with_a_pydronecan_node(capsys: pytest.CaptureFixture[str]) -> None:
    """A pydronecan node publishes BatteryInfoAux + BatteryInfo on python-can's in-process virtual bus while
    ``battgen can --bus`` listens. The node keeps publishing until the command has returned, so a loaded machine
    (a late start of either side) changes how many transfers are seen, never whether they are right; the reader
    may join in the middle of a transfer and stop in the middle of one, the only transport problems allowed."""
    virtual = pytest.importorskip("can.interfaces.virtual")
    # pydronecan's python-can driver flushes after every send; the virtual bus has nothing to flush
    original = virtual.VirtualBus.flush_tx_buffer
    virtual.VirtualBus.flush_tx_buffer = lambda self: None  # type: ignore[method-assign]
    channel = f"battgen-{time.monotonic_ns()}"
    stop = threading.Event()

    def publish() -> None:
        node = dronecan.make_node(channel, node_id=42, bustype="virtual", bitrate=1_000_000)
        try:
            deadline = time.monotonic() + 60  # bounded even if the reader never returns
            while not stop.is_set() and time.monotonic() < deadline:
                node.broadcast(dronecan.ardupilot.equipment.power.BatteryInfoAux(voltage_cell=[3.8] * 4, battery_id=1))
                node.broadcast(dronecan.uavcan.equipment.power.BatteryInfo(voltage=15.2, battery_id=1))
                time.sleep(0.02)
        finally:
            node.close()

    thread = threading.Thread(target=publish, daemon=True)
    thread.start()
    try:
        code = main(["can", "--bus", f"virtual:{channel}", "--duration", "2.5", "--records", "--format", "json"])
    finally:
        stop.set()
        thread.join(timeout=10)
        virtual.VirtualBus.flush_tx_buffer = original  # type: ignore[method-assign]
    out = capsys.readouterr().out
    lines = out.splitlines()
    records = [json.loads(x) for x in lines if x.startswith('{"t"')]
    report = json.loads("\n".join(x for x in lines if not x.startswith('{"t"')))["captures"][0]
    infos = [r for r in records if r["type"] == "BatteryInfo"]
    assert len(infos) >= 3
    assert all(r["node"] == 42 and abs(r["message"]["voltage"] - 15.2) < 0.01 for r in infos)
    # joining mid-transfer, and stopping mid-transfer: each at most once per message type
    counts = report["problem_counts"]
    assert set(counts) <= {"can-missing-start", "can-missing-end"} and all(n <= 2 for n in counts.values())
    assert code == (1 if report["problem_counts"] else 0)


def test_gzip_capture_is_looked_through(tmp_path: Path) -> None:
    plain = _write(tmp_path / "bus.log", _messages())
    packed = tmp_path / "copy.log.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    assert main(["validate", str(packed)]) == 0


def test_a_line_numbered_candump_names_the_line_and_the_form_expected(tmp_path: Path) -> None:
    # pretty_j1939's test logs number their lines ("1 (stamp) vcan0 ID#DATA"): not candump -l, which python-can
    # reads; the error says where and what was expected instead of python-can's "too many values to unpack"
    path = tmp_path / "numbered.log"
    path.write_text("(1612543138.000000) vcan0 0CF00400#0041FF20481400F0\n2 (1612543138.001000) vcan0 18F00400#00\n")
    with pytest.raises(InputError) as err:
        list(read_capture(path, "numbered.log"))
    assert err.value.line == 2 and "expected a candump -l line" in err.value.message


def test_converted_capture_keeps_each_record_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """BatteryInfo has no timestamp field: a uORB record converted from a capture is stamped with the frame's time
    since the capture's start (µs), not 0 on every record."""
    path = _write(tmp_path / "bus.log", _messages())
    assert main(["convert", "--from", "dronecan", "--to", "uorb", str(path)]) == 0
    records = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    stamps = [r["timestamp"] for r in records]
    assert len(stamps) == CYCLES * len(NODES) and stamps == sorted(stamps) and len(set(stamps)) == len(stamps)
    # the messages are 0.5 ms apart, the first frame at 0.5 ms after the first message: each BatteryInfo starts
    # after its node's BatteryInfoAux (a transfer of several frames)
    assert 0 < stamps[0] < 10_000 and stamps[-1] < CYCLES * 100_000


def test_error_and_remote_frames_are_counted_and_reported(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    messages = _messages()
    t = messages[-1].timestamp
    messages.append(can.Message(timestamp=t + 0.001, is_error_frame=True, channel="can0"))
    messages.append(can.Message(timestamp=t + 0.002, arbitration_id=0x1004E37F, is_extended_id=True,
                                is_remote_frame=True, dlc=8, channel="can0"))  # fmt: skip
    path = _write(tmp_path / "bus.asc", messages)
    assert main(["can", "--format", "json", str(path)]) == 0  # warnings: no transfer was lost by them
    report = json.loads(capsys.readouterr().out)["captures"][0]
    assert report["problem_counts"] == {"can-error-frame": 1, "can-remote-frame": 1}
    assert report["frames"] == len(messages)


def test_can_command_takes_the_documented_input_format(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path / "bus.csv", _messages())
    assert main(["can", "--input-format", "can", "--format", "json", str(path)]) == 0
    report = json.loads(capsys.readouterr().out)["captures"][0]
    assert sum(s["count"] for s in report["streams"]) == 2 * CYCLES * len(NODES)
