"""battgen export --engine dask: the per-log export as tasks on a real dask.distributed
LocalCluster with two workers writes the same dataset as the local run, table by table.

The workers are threads of this process (``processes=False``): worker processes cost ~30 s of
start-up on the 2-core CI machine. ``BATTGEN_DASK_PROCESSES=1`` runs the same test with two
worker processes (what ``battgen export --engine dask`` starts)."""

from __future__ import annotations

import os
from pathlib import Path

import pyarrow.parquet as pq
from fleet_samples import LOGS, jsonl, tlog

from codegen.apps.export.distributed import export_dask
from codegen.apps.export.engine import ExportOptions, export_logs

PROCESSES = os.environ.get("BATTGEN_DASK_PROCESSES") == "1"


def test_two_worker_local_cluster_matches_the_local_run(tmp_path: Path) -> None:
    inputs = [tlog(tmp_path / "a.tlog").as_posix(), jsonl(tmp_path / "b.jsonl").as_posix()]
    inputs += [p.as_posix() for p in LOGS]
    (tmp_path / "bad.ulg").write_bytes(b"garbage")
    inputs.append((tmp_path / "bad.ulg").as_posix())
    local = export_logs(inputs, ExportOptions(tmp_path / "local"))
    seen: list[str] = []
    remote = export_dask(
        inputs, ExportOptions(tmp_path / "dask"), workers=2, processes=PROCESSES, progress=lambda r: seen.append(r.path)
    )
    assert sorted(seen) == sorted(inputs)
    assert [(r.path, r.status, r.log, r.rows) for r in remote] == [(r.path, r.status, r.log, r.rows) for r in local]
    assert remote[-1].status == "failed"
    for r in local:
        if r.status != "exported":
            continue
        a = pq.read_table(tmp_path / "local" / "battery" / f"log={r.log}")
        b = pq.read_table(tmp_path / "dask" / "battery" / f"log={r.log}")
        assert a.equals(b) and a.schema.equals(b.schema, check_metadata=True)
