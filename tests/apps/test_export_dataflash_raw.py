"""battgen export --raw on DataFlash logs: the BAT and BCL records as tables of every field the log's
FMT records declare, compared with pymavlink's own DataFlash reader on the same file."""

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


def _log(path: Path) -> Path:
    w = DataflashWriter()
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
        files = list((out / "raw" / f"dataflash.{kind}").glob("log=*/part-0.parquet"))
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
