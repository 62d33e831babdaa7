"""battgen export on DataFlash logs, against pymavlink's own DataFlash reader on the same file: --raw
writes the BAT and BCL records as tables of every field the log's FMT records declare; the time of
day comes from the log's GPS week and time of week, as pymavlink's clock gives it."""

from __future__ import annotations

import sys
from pathlib import Path

import duckdb
import pyarrow.parquet as pq
import pytest

from codegen.cli.main import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from dataflash_writer import DataflashWriter

CELLS = ("V1", "V2", "V3", "V4", "V5", "V6", "V7", "V8", "V9", "V10", "V11", "V12")


def _log(path: Path, gps: bool = False) -> Path:
    w = DataflashWriter()
    if gps:  # a fix 0.45 s into the log: GPS week 2290, Wednesday noon (GPS time)
        w.define("GPS", "QBIH", ("TimeUS", "Status", "GMS", "GWk"))
        w.write("GPS", 450_000, 3, 3 * 86_400_000 + 43_200_000, 2290)
    w.define("BAT", "QBfffffffBB", ("TimeUS", "Inst", "Volt", "VoltR", "Curr", "CurrTot", "EnrgTot", "Temp", "Res",
                                    "RemPct", "H"))  # fmt: skip
    w.define("BCL", "QBfHHHHHHHHHHHH", ("TimeUS", "Instance", "Volt", *CELLS))
    for k in range(20):
        t = 100_000 * k
        for inst in (0, 1):
            w.write("BAT", t, inst, 16.4 - k * 0.01, 16.5, 7.5 + inst, k * 2.1, k * 30.0, 31.5, 0.012, 90 - k, 1)
            w.write("BCL", t + 10, inst, 16.4 - k * 0.01, 4100, 4101, 4099 - k, 4100, *([65535] * 8))
    return w.save(path)


def _pymavlink(path: Path, kind: str) -> list[dict[str, object]]:
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(str(path))
    out = []
    while (msg := conn.recv_match(type=kind)) is not None:
        values = msg.to_dict()
        values.pop("mavpackettype")
        out.append(values)
    return out


def test_bat_and_bcl_records_every_field_as_pymavlink_reads_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = _log(tmp_path / "flight.bin")
    out = tmp_path / "ds"
    assert main(["export", "-o", str(out), str(log), "--raw"]) == 0, capsys.readouterr().err
    for kind, instance in (("BAT", "Inst"), ("BCL", "Instance")):
        files = list((out / "raw" / f"dataflash.{kind}").glob("log=*/part-*.parquet"))
        assert len(files) == 1
        table = pq.read_table(files[0])
        reference = _pymavlink(log, kind)
        assert len(reference) == 40
        fields = [c for c in table.column_names if c not in ("log", "instance", "t")]
        assert fields == list(reference[0])  # every column the FMT record declares, in its order
        assert table.select(fields).to_pylist() == reference
        assert table["instance"].to_pylist() == [r[instance] for r in reference]
        assert table["t"].to_pylist() == pytest.approx([r["TimeUS"] / 1e6 for r in reference])
    # the sentinels stay: BCL's unused cells are 65535 as logged
    con = duckdb.connect()
    rows = con.sql(f"SELECT DISTINCT V5, V12 FROM read_parquet('{out}/raw/dataflash.BCL/*/*.parquet')").fetchall()
    assert rows == [(65535, 65535)]
    # and the normalised table is unchanged by --raw
    count = con.sql(f"SELECT count(*) FROM read_parquet('{out}/battery/*/*.parquet')").fetchall()
    assert count == [(40,)]


def test_time_of_day_from_the_gps_clock(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = _log(tmp_path / "gps.bin", gps=True)
    out = tmp_path / "ds"
    assert main(["export", "-o", str(out), str(log), "--partition", "day"]) == 0, capsys.readouterr().err
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(str(log))
    reference = []
    while (msg := conn.recv_match(type="BAT")) is not None:
        reference.append(msg._timestamp)
    assert len(reference) == 40 and reference[0] > 1.7e9  # pymavlink found the GPS clock
    con = duckdb.connect()
    rows = con.sql(
        f"SELECT epoch_us(time), day FROM read_parquet('{out}/battery/*/*/*.parquet', hive_partitioning = true) "
        "ORDER BY t, battery"
    ).fetchall()
    assert [us / 1e6 for us, _ in rows] == pytest.approx(reference, abs=1e-6)
    assert {str(day) for _, day in rows} == {"2023-11-29"}  # GPS week 2290 began on Sunday 2023-11-26
