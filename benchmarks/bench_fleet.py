"""Fleet export: ULog -> Parquet with battgen export against the hand path, a synthetic fleet with
--jobs 2 and with Dask on two workers, and the DuckDB per-flight summary, in one run.

Run: python benchmarks/bench_fleet.py [--records N] [--logs N] [--log-records N] [--repeat N] [--no-dask]
Prints:
- battery records per CPU second from ULog to Parquet (one process): ``battgen export`` of one
  log (content id, index, columns, the IR's mappings over columns, Arrow, zstd Parquet) against what a
  user writes by hand on the same log (pyulog -> pandas DataFrame per instance -> ``to_parquet``,
  raw fields, no units or sentinels); on the synthetic log (--records records, two instances), on a
  mixed one (--records / 20 battery records among 19x as many of another topic, as in a flight log)
  and on the two real PX4 logs; the ratio. Targets (issue 14): >= 5x the hand path, >= 2 M records/s/core.
- a synthetic fleet of --logs logs (--log-records records each, two instances) exported with --jobs 2
  and with a two-worker Dask LocalCluster (worker processes): wall time, records/s, the peak memory
  (max RSS) of the busiest worker, at a quarter of the fleet and at the whole fleet (flat in the
  number of logs), and the rows DuckDB reads back (must equal the records written);
- DuckDB's per-flight summary (the ``flights`` view) over that fleet: time, and rows (must equal
  the (log, battery) pairs).
"""

from __future__ import annotations

import argparse
import resource
import shutil
import tempfile
import time
import timeit
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from pyulog import ULog

from codegen.apps.export.engine import ExportOptions, export_logs, export_one, finish
from codegen.apps.export.query import connect
from codegen.inputs.ulog.index import compiled
from generated import _ulog
from generated.uorb import BatteryInfo, BatteryStatus

# the shared real PX4 logs, beside the repository (as CI has them)
REAL_LOGS = Path(__file__).resolve().parents[2] / "shared" / "data" / "ulog"

TOPIC = "battery_status"
REPEAT = [3]


def sample(i: int) -> BatteryStatus:
    msg = BatteryStatus(timestamp=1_000_000 + 10_000 * i, connected=True, voltage_v=16.8 - i * 1e-5, cell_count=4)
    msg.current_a, msg.remaining, msg.temperature, msg.id = 12.5 + (i % 7), 0.9 - i * 1e-7, 31.5, 1 + i % 2
    msg.discharged_mah = i * 0.01
    msg.voltage_cell_v[:4] = [4.2 - i * 1e-6, 4.2, 4.19, 4.2]
    return msg


def write_log(path: Path, records: int, tag: str, flight: int = 0, others: int = 0) -> None:
    """A log of ``records`` battery_status records (two instances) of the vehicle ``tag``; ``flight``
    makes the content (and so the log's id) of each flight its own; ``others`` records of another
    topic (battery_info) after each battery record, as a real log's other topics outnumber it."""
    template = [sample(i) for i in range(min(records, 4096))]
    other = BatteryInfo(timestamp=0, id=1)
    with _ulog.Writer(
        str(path), timestamp=1_000_000 + flight, info={"sys_name": "bench", "sys_uuid": tag},
        messages=(BatteryStatus, BatteryInfo),
    ) as w:  # fmt: skip
        for i in range(records):
            msg = template[i % len(template)]
            msg.timestamp = 1_000_000 + 5_000 * i
            w.write(msg, multi_id=i & 1)
            for j in range(others):
                other.timestamp = msg.timestamp + j
                w.write(other)


def hand_path(path: str, out: Path) -> int:
    """What a user writes by hand: pyulog, a DataFrame per instance, pandas' to_parquet."""
    ulog = ULog(path, message_name_filter_list=[TOPIC])
    rows = 0
    for d in ulog.data_list:
        frame = pd.DataFrame(d.data)
        frame.to_parquet(out / f"{TOPIC}_{d.multi_id}.parquet")
        rows += len(frame)
    return rows


def _max_rss_mb() -> float:
    """The peak resident memory of the calling process (a Dask worker), MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def best(fn: Any) -> float:
    """Best of REPEAT runs, in CPU seconds of this process (its threads included): records per
    second per core, and steady on a machine other jobs share."""
    return min(timeit.repeat(fn, number=1, repeat=REPEAT[0], timer=time.process_time))


def single_log(path: Path, tmp: Path, key: str, r: dict[str, float]) -> None:
    counter = [0]

    def ours() -> int:
        counter[0] += 1
        out = tmp / f"ours-{key}-{counter[0]}"
        res = export_one(path.as_posix(), ExportOptions(out))
        assert res.status == "exported", res.error
        shutil.rmtree(out)
        return res.rows

    def hand() -> int:
        out = tmp / f"hand-{key}"
        out.mkdir(exist_ok=True)
        rows = hand_path(path.as_posix(), out)
        shutil.rmtree(out)
        return rows

    rows = ours()
    assert rows == hand(), "the hand path and ours disagree on the number of records"
    same_values(path, tmp / f"values-{key}")
    r[f"{key}_records"] = rows
    r[f"{key}_ours_rps"] = rows / best(ours)
    r[f"{key}_hand_rps"] = rows / best(hand)


def same_values(path: Path, out: Path) -> None:
    """The voltage and charge each path wrote, value for value (as float32, the log's type), in time order."""
    import pyarrow.parquet as pq

    res = export_one(path.as_posix(), ExportOptions(out / "ours"))
    assert res.status == "exported", res.error
    ours = pd.concat(pq.read_table(p).to_pandas() for p in sorted((out / "ours").rglob("*.parquet")))
    ours = ours.sort_values(["t", "battery"], kind="stable")
    (out / "hand").mkdir(parents=True)
    hand_path(path.as_posix(), out / "hand")
    hand = pd.concat(pd.read_parquet(p) for p in sorted((out / "hand").glob("*.parquet")))
    hand = hand.sort_values(["timestamp", "id"], kind="stable")
    for mine, theirs in (("pack_voltage", "voltage_v"), ("state_of_charge", "remaining")):
        a = ours[mine].to_numpy(np.float64).astype(np.float32)
        b = hand[theirs].to_numpy(np.float64).astype(np.float32)
        np.testing.assert_array_equal(a, b, err_msg=f"{path.name}: {mine} against pyulog's {theirs}")
    shutil.rmtree(out)


def fleet(tmp: Path, logs: int, per_log: int, dask: bool, r: dict[str, float]) -> None:
    folder = tmp / "fleet"
    folder.mkdir()
    paths = []
    for i in range(logs):
        p = folder / f"flight{i:05d}.ulg"
        write_log(p, per_log, f"vehicle{i % 17:02d}", flight=i)
        paths.append(p.as_posix())
    total = logs * per_log
    r["fleet_logs"], r["fleet_records"] = logs, total
    for label, subset in (("quarter", paths[: max(1, logs // 4)]), ("full", paths)):
        out = tmp / f"jobs-{label}"
        t = time.perf_counter()
        results = export_logs(subset, ExportOptions(out), jobs=2)
        r[f"jobs_{label}_s"] = time.perf_counter() - t
        assert all(x.status == "exported" for x in results), [x for x in results if x.status != "exported"][:3]
        r[f"jobs_{label}_rss_mb"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        r[f"jobs_{label}_logs"] = len(subset)
    out = tmp / "jobs-full"
    finish(out)
    con = connect(out)
    r["jobs_rows"] = con.execute("SELECT count(*) FROM battery").fetchall()[0][0]
    t = time.perf_counter()
    flights = con.execute("SELECT * FROM flights").fetchall()
    r["duckdb_flights_s"] = time.perf_counter() - t
    r["duckdb_flights_rows"] = len(flights)
    con.close()
    if dask:
        from distributed import Client, LocalCluster

        from codegen.apps.export.distributed import run_on

        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                r["dask_start_rss_mb"] = max(client.run(_max_rss_mb).values())
                for label, subset in (("quarter", paths[: max(1, logs // 4)]), ("full", paths)):
                    out = tmp / f"dask-{label}"
                    t = time.perf_counter()
                    results = run_on(client, subset, ExportOptions(out))
                    r[f"dask_{label}_s"] = time.perf_counter() - t
                    assert all(x.status == "exported" for x in results)
                    r[f"dask_{label}_rss_mb"] = max(client.run(_max_rss_mb).values())
        con = connect(tmp / "dask-full")
        r["dask_rows"] = con.execute("SELECT count(*) FROM battery").fetchall()[0][0]
        con.close()


def run(records: int, logs: int, per_log: int, dask: bool) -> dict[str, float]:
    r: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        if logs:  # first, while this process is small: workers forked from it start from its memory
            fleet(tmp, logs, per_log, dask, r)
        synthetic = tmp / "synthetic.ulg"
        write_log(synthetic, records, "bench")
        single_log(synthetic, tmp, "synthetic", r)
        mixed = tmp / "mixed.ulg"  # one battery record in twenty, as in a flight log's many topics
        write_log(mixed, records // 20, "bench", others=19)
        single_log(mixed, tmp, "mixed", r)
        for log in sorted(REAL_LOGS.glob("*.ulg")):
            single_log(log, tmp, log.stem, r)
    return r


def report(r: dict[str, float]) -> None:
    walk = "compiled C walk" if compiled() else "generated Python walk (the C extension was not built)"
    print(f"ULog -> Parquet, battery records per CPU second (one process, best of the repeats; {walk}):")
    for key in [k.removesuffix("_records") for k in r if k.endswith("_records") and not k.startswith("fleet")]:
        ours, hand = r[f"{key}_ours_rps"], r[f"{key}_hand_rps"]
        print(
            f"  {key} ({int(r[f'{key}_records'])} records): battgen export {ours / 1e6:7.3f} M/s, "
            f"pyulog -> pandas -> to_parquet {hand / 1e6:7.3f} M/s, {ours / hand:5.2f}x the hand path"
        )
    if "fleet_logs" not in r:
        return
    logs, total = int(r["fleet_logs"]), int(r["fleet_records"])
    print(f"synthetic fleet: {logs} logs, {total} records:")
    for engine in ("jobs", "dask"):
        if f"{engine}_full_s" not in r:
            continue
        name = "--jobs 2" if engine == "jobs" else "Dask, 2 worker processes"
        for label in ("quarter", "full"):
            n = int(r.get(f"{engine}_{label}_logs", logs if label == "full" else max(1, logs // 4)))
            secs = r[f"{engine}_{label}_s"]
            print(
                f"  {name:<26} {n:5d} logs: {secs:7.2f} s, {n * total / logs / secs / 1e6:6.3f} M records/s, "
                f"peak worker memory {r[f'{engine}_{label}_rss_mb']:7.1f} MB"
            )
        if engine == "dask":
            print(f"  {name:<26} worker memory when the cluster started: {r['dask_start_rss_mb']:7.1f} MB")
        rows = int(r[f"{engine}_rows"])
        same = "equal" if rows == total else "DIFFERENT"
        print(f"  {name:<26} rows read back by DuckDB: {rows} (records written: {total}, {same})")
    pairs = 2 * logs
    rows = int(r["duckdb_flights_rows"])
    print(
        f"DuckDB per-flight summary (flights view): {r['duckdb_flights_s']:.3f} s, {rows} rows "
        f"((log, battery) pairs: {pairs}, {'equal' if rows == pairs else 'DIFFERENT'})"
    )


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--records", type=int, default=1_000_000, help="records in the synthetic single log")
    parser.add_argument("--logs", type=int, default=1000, help="logs in the synthetic fleet (0: none)")
    parser.add_argument("--log-records", type=int, default=2000, help="records per fleet log")
    parser.add_argument("--repeat", type=int, default=3, help="timing repeats (the best one counts)")
    parser.add_argument("--no-dask", action="store_true", help="skip the Dask run")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.records, args.logs, args.log_records, args.repeat, args.no_dask = 2000, 3, 200, 1, True
    REPEAT[0] = args.repeat
    results = run(args.records, args.logs, args.log_records, not args.no_dask)
    report(results)
    return results


if __name__ == "__main__":
    main()
