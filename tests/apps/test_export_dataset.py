"""battgen export's dataset: the shared real logs export with every battery instance, DuckDB reads
the documented columns back with units in the field metadata and nulls where the source said
unknown; tlog and JSON Lines inputs; incremental runs; bad logs reported, never fatal."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import duckdb
import pyarrow.parquet as pq
import pytest
import pyulog
from conftest import ROOT
from fleet_samples import DOCUMENTED, LOGS, jsonl, needs_logs, tlog

from codegen.apps.export.content import content_id
from codegen.apps.export.engine import ExportOptions, export_logs, finish
from codegen.apps.export.query import run_query
from codegen.errors import BattgenError


@needs_logs
def test_real_logs_every_instance_units_and_nulls(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    results = export_logs([p.as_posix() for p in LOGS], ExportOptions(out, raw=True))
    finish(out)
    assert [r.status for r in results] == ["exported"] * len(LOGS)
    con = duckdb.connect()
    table = con.sql(f"SELECT * FROM read_parquet('{out}/battery/*/*.parquet', hive_partitioning = true)")
    assert DOCUMENTED <= set(table.columns)
    for log in LOGS:  # every battery_status instance, every record, as pyulog reads them
        ref = pyulog.ULog(log.as_posix(), ["battery_status"])
        expected = {d.multi_id: d for d in ref.data_list}
        rows = con.sql(
            f"SELECT battery, count(*), list(pack_voltage ORDER BY t), list(t ORDER BY t) FROM read_parquet("
            f"'{out}/battery/*/*.parquet', hive_partitioning = true) WHERE source = '{log.name}' GROUP BY battery"
        ).fetchall()
        assert len(rows) == len(expected)
        for battery, count, volts, times in rows:
            data = next(d for d in expected.values() if d.data["id"][0] - 1 == battery or d.multi_id == battery)
            assert count == len(data.data["timestamp"])
            want = [float(v) if v != 0 else None for v in data.data["voltage_v"]]
            assert volts == pytest.approx(want)
            start = ref.start_timestamp
            assert times == pytest.approx([(ts - start) / 1e6 for ts in data.data["timestamp"]])
    schema = pq.read_schema(next((out / "battery").rglob("*.parquet")))
    meta = {k.decode(): v.decode() for k, v in schema.field("pack_voltage").metadata.items()}
    assert meta["unit"] == "V" and meta["quantity"] == "voltage"
    assert json.loads(meta["source_fields"])["uorb.BatteryStatus"] == ["voltage_v"]
    assert schema.field("temperature").metadata[b"unit"] == b"K"
    assert schema.field("discharged").metadata[b"unit"] == b"C"
    # the SITL log says NaN temperature and 0 V cells: unknown, so null
    sitl = run_query(
        out,
        "SELECT count(*), count(temperature), sum(list_count(cell_voltages)) "
        "FROM battery WHERE source = 'sample_px4_events.ulg'",
    ).rows[0]
    assert sitl[0] > 0 and sitl[1] == 0 and sitl[2] == 0
    flights = run_query(out, "SELECT log, battery, records, min_voltage, peak_current FROM flights").rows
    assert len(flights) == sum(
        len({d.multi_id for d in pyulog.ULog(p.as_posix(), ["battery_status"]).data_list}) for p in LOGS
    )
    assert (out / "views.sql").is_file() and list((out / "raw" / "uorb.BatteryStatus").iterdir())


def test_tlog_and_jsonl(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    inputs = [tlog(tmp_path / "a.tlog").as_posix(), jsonl(tmp_path / "b.jsonl").as_posix()]
    results = export_logs(inputs, ExportOptions(out))
    assert [(r.status, r.rows) for r in results] == [("exported", 6), ("exported", 4)]
    rows = run_query(
        out,
        "SELECT source, message, vehicle, battery, t, time, pack_voltage, cell_voltages, current, "
        "state_of_charge, temperature FROM battery ORDER BY source, t",
    ).rows
    first = rows[0]
    assert first[:5] == ("a.tlog", "mavlink.BATTERY_STATUS", "mavlink:7", 1, 0.0)
    assert first[5].year == 2023
    assert first[6] == pytest.approx(4.1 + 4.09 + 4.08) and first[7] == pytest.approx([4.1, 4.09, 4.08])
    assert first[8] == pytest.approx(15.0) and first[9] is None and first[10] is None  # -1 and INT16_MAX: unknown
    assert rows[1][10] == pytest.approx(298.15)
    j = [r for r in rows if r[0] == "b.jsonl"]
    assert [r[1] for r in j] == ["uorb.BatteryStatus"] * 4 and j[0][9] == pytest.approx(0.8) and j[1][9] is None
    assert [r[4] for r in j] == [0.0, 1.0, 2.0, 3.0]
    ir = run_query(
        out,
        "SELECT internal_resistance FROM flights WHERE log = (SELECT log FROM battery WHERE source = 'a.tlog' LIMIT 1)",
    )
    assert ir.rows[0][0] == pytest.approx((4.08 + 4.07 + 4.08 - (4.07 + 4.06 + 4.08)) / 20.0)  # one 20 A step


def test_a_tlog_stamp_past_int64_is_an_unknown_time(tmp_path: Path) -> None:
    good = tlog(tmp_path / "a.tlog").read_bytes()
    bad = tmp_path / "b.tlog"  # the first frame's uint64 stamp all ones (a damaged log's; once an OverflowError)
    bad.write_bytes(b"\xff" * 8 + good[8:])
    [res] = export_logs([bad.as_posix()], ExportOptions(tmp_path / "ds"))
    assert (res.status, res.rows) == ("exported", 6)
    rows = run_query(tmp_path / "ds", "SELECT t, time FROM battery ORDER BY t NULLS FIRST").rows
    assert rows[0] == (None, None)  # the frame is kept, its time unknown
    assert rows[1][0] == 0.0 and all(t is not None and time is not None for t, time in rows[1:])


def test_incremental_and_bad_logs(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    good = jsonl(tmp_path / "a.jsonl")
    (tmp_path / "bad.ulg").write_bytes(b"not a ulog at all, nothing here")
    (tmp_path / "empty.tlog").write_bytes(b"")
    first = export_logs([good.as_posix(), (tmp_path / "bad.ulg").as_posix()], ExportOptions(out))
    assert [r.status for r in first] == ["exported", "failed"]
    assert "bad.ulg" in first[1].error and "ULog" in first[1].error
    copy = tmp_path / "copy.jsonl"
    copy.write_bytes(good.read_bytes())
    second = export_logs([good.as_posix(), copy.as_posix(), (tmp_path / "empty.tlog").as_posix()], ExportOptions(out))
    assert [r.status for r in second][:2] == ["skipped", "skipped"]
    assert run_query(out, "SELECT count(*) FROM battery").rows == [(4,)]


def test_log_ids_are_xxh128_and_sha256_where_the_dataset_was_named_so(tmp_path: Path) -> None:
    # the upstream test vectors: xxHash's cli/xsum_sanity_check.c (XXH3-128 of the empty input) and
    # FIPS 180-2's "abc"
    (tmp_path / "empty.bin").write_bytes(b"")
    assert content_id(tmp_path / "empty.bin") == "99aa06d3014798d8"
    (tmp_path / "abc.bin").write_bytes(b"abc")
    assert content_id(tmp_path / "abc.bin", scheme="sha256") == "ba7816bf8f01cfea"
    # a new dataset records its hash; one made before the record keeps SHA-256, so its logs are still skipped
    good = jsonl(tmp_path / "a.jsonl")
    new = export_logs([good.as_posix()], ExportOptions(tmp_path / "new"))
    assert json.loads((tmp_path / "new" / "dataset.json").read_text())["content_id"] == "xxh128"
    assert new[0].log == content_id(good)
    old = tmp_path / "old"
    first = export_logs([good.as_posix()], ExportOptions(old, content_id="sha256"))
    (old / "dataset.json").unlink()
    again = export_logs([good.as_posix()], ExportOptions(old))
    assert first[0].log == again[0].log == content_id(good, scheme="sha256") != new[0].log
    assert again[0].status == "skipped"
    assert json.loads((old / "dataset.json").read_text())["content_id"] == "sha256"
    with pytest.raises(BattgenError, match="names its logs by sha256"):
        export_logs([good.as_posix()], ExportOptions(old, content_id="xxh128"))


def test_jobs_two_gives_the_same_dataset(tmp_path: Path) -> None:
    inputs = [tlog(tmp_path / "a.tlog").as_posix(), jsonl(tmp_path / "b.jsonl").as_posix()]
    inputs += [p.as_posix() for p in LOGS]
    one = export_logs(inputs, ExportOptions(tmp_path / "one"))
    two = export_logs(inputs, ExportOptions(tmp_path / "two"), jobs=2)
    assert [(r.log, r.rows) for r in one] == [(r.log, r.rows) for r in two]
    for r in one:
        a = pq.read_table(tmp_path / "one" / "battery" / f"log={r.log}")
        b = pq.read_table(tmp_path / "two" / "battery" / f"log={r.log}")
        assert a.equals(b)


def _dataflash_writer() -> Any:
    spec = importlib.util.spec_from_file_location("dataflash_writer", ROOT / "tests" / "inputs" / "dataflash_writer.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_dataflash_bat_records(tmp_path: Path) -> None:
    rows = [(1.0, 0, 12.6, 5.0, 100.0), (2.0, 0, 12.4, 25.0, 110.0), (2.0, 1, 16.1, 3.0, 50.0)]
    path = _dataflash_writer().battery_log(tmp_path / "f.bin", {"BATT_LOW_VOLT": 10.5}, rows, [(1.5, True)])
    out = tmp_path / "ds"
    results = export_logs([path.as_posix()], ExportOptions(out, raw=True))
    assert [(r.status, r.rows) for r in results] == [("exported", 3)]
    got = run_query(
        out, "SELECT message, battery, t, armed, pack_voltage, current, discharged FROM battery ORDER BY battery, t"
    ).rows
    assert [g[:4] for g in got] == [  # disarmed before its first ARM record (inputs/dataflash/arming.py)
        ("dataflash.BAT", 0, 1.0, False),
        ("dataflash.BAT", 0, 2.0, True),
        ("dataflash.BAT", 1, 2.0, True),
    ]
    assert [g[4:] for g in got] == [pytest.approx((v, a, mah * 3.6)) for _, _, v, a, mah in rows]
    flights = run_query(out, "SELECT battery, internal_resistance FROM flights ORDER BY battery").rows
    assert flights[0][1] == pytest.approx(0.2 / 20.0) and flights[1][1] is None
