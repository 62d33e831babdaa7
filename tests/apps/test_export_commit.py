"""The export's commit protocol: a log is visible whole or not at all, a re-export swaps versions, a crash
at any file-system step leaves the old or the new state (and the next run completes it), dataset.json is
never re-defaulted, and writers on one dataset take turns."""

from __future__ import annotations

import json
import os
import random
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from fleet_samples import jsonl

from codegen.apps.export.durable import LOCK_FILE, writers_lock
from codegen.apps.export.engine import ExportOptions, export_logs, finish
from codegen.apps.export.manifest import committed
from codegen.apps.export.query import run_query
from codegen.cli.main import main
from codegen.errors import BattgenError

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cli"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from test_failsafe_replays import PARAMS, write_bin, write_tlog

State = dict[str, tuple[int, int, int]]  # source -> (battery rows, failsafe replays, failsafe events)


def state(out: Path) -> State:
    """What a reader of the dataset sees, per log: through the views, as battgen query reads it."""
    if not committed(out)["battery"]:
        return {}
    rows = run_query(
        out,
        "SELECT b.source, b.n, (SELECT count(*) FROM failsafe_replays r WHERE r.log = b.log), "
        "(SELECT count(*) FROM failsafe_events e WHERE e.log = b.log) "
        "FROM (SELECT source, log, count(*) AS n FROM battery GROUP BY source, log) AS b ORDER BY b.source",
    ).rows
    return {str(s): (int(n), int(r), int(e)) for s, n, r, e in rows}


def all_files(out: Path) -> set[str]:
    return {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}


def leftovers(out: Path) -> set[str]:
    """Temporary files and table files no marker names."""
    named = {f for files in committed(out).values() for f in files}
    tables = {f for f in all_files(out) if f.endswith(".parquet")}
    return {f for f in all_files(out) if "/.tmp-" in "/" + f} | (tables - named)


@pytest.fixture
def flights(tmp_path: Path) -> tuple[list[Path], Path]:
    logs = tmp_path / "logs"
    logs.mkdir()
    params = tmp_path / "rover.param"
    params.write_text("".join(f"{k},{v}\n" for k, v in PARAMS.items()), encoding="utf-8")
    return [write_tlog(logs / "flight.tlog"), write_bin(logs / "flight.bin")], params


# -- versions, dataset.json, leftovers ---------------------------------------------------------------------------


def test_a_reexport_swaps_versions_and_removes_the_old(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    logs, params = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), *map(str, logs)]) == 0
    before = state(out)
    old_files = all_files(out)
    markers = {p.name: json.loads(p.read_text())["version"] for p in (out / "logs").glob("*.json")}
    assert main(["export", "-q", "-o", str(out), *map(str, logs), "--failsafe", str(params)]) == 0
    after = state(out)
    assert {s: v[0] for s, v in after.items()} == {s: v[0] for s, v in before.items()}  # the same records
    assert all(v[1] > 0 for v in after.values()) and all(v[1] == 0 for v in before.values())
    for p in (out / "logs").glob("*.json"):
        assert json.loads(p.read_text())["version"] != markers[p.name]
    # the old version's files are gone, one battery file per log, nothing left over
    old_parts = {f for f in old_files if f.startswith("battery/")}
    assert not old_parts & all_files(out)
    assert len([f for f in all_files(out) if f.startswith("battery/")]) == 2
    assert leftovers(out) == set()


def test_an_unreadable_dataset_json_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ds"
    log = jsonl(tmp_path / "a.jsonl")
    assert main(["export", "-q", "-o", str(out), str(log)]) == 0
    for text in ("", "{not json", '{"partition": "week", "content_id": "xxh128"}', "[]"):
        (out / "dataset.json").write_text(text, encoding="utf-8")
        with pytest.raises(BattgenError, match=r"dataset\.json: expected the dataset.s layout"):
            export_logs([log.as_posix()], ExportOptions(out))
        code = main(["export", "-q", "-o", str(out), str(log)])
        err = capsys.readouterr().err
        assert code == 2 and "dataset.json: expected the dataset's layout" in err and "Traceback" not in err
        assert (out / "dataset.json").read_text(encoding="utf-8") == text  # never re-defaulted
        assert main(["query", str(out), "SELECT 1"]) == 2
        assert "dataset.json" in capsys.readouterr().err


def test_a_day_dataset_without_its_dataset_json_keeps_its_layout(
    tmp_path: Path, flights: tuple[list[Path], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    logs, _ = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), str(logs[0]), "--partition", "day"]) == 0
    (out / "dataset.json").unlink()  # lost: the markers still name day partitions
    assert main(["export", "-q", "-o", str(out), str(logs[1])]) == 2
    assert "partitioned by day" in capsys.readouterr().err
    assert main(["export", "-q", "-o", str(out), str(logs[1]), "--partition", "day"]) == 0
    assert json.loads((out / "dataset.json").read_text())["partition"] == "day"
    assert set(state(out)) == {"flight.tlog", "flight.bin"}


def test_leftovers_are_never_read_and_removed_at_the_next_start(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    a, b = jsonl(tmp_path / "a.jsonl"), jsonl(tmp_path / "b.jsonl")
    b.write_text(b.read_text().replace("12.0", "11.0"), encoding="utf-8")  # other content: another log
    export_logs([a.as_posix()], ExportOptions(out))
    before = state(out)
    [part] = (out / "battery").rglob("*.parquet")
    # a stopped run: its temporary folder, and a version it moved in without its marker
    (out / ".tmp-deadbeef-x").mkdir()
    (out / ".tmp-deadbeef-x" / "part-0.parquet").write_bytes(part.read_bytes())
    (out / "logs" / ".tmp-deadbeef.json.1234").write_text("{", encoding="utf-8")
    stray = part.with_name("part-0123.parquet")
    stray.write_bytes(part.read_bytes())
    assert state(out) == before  # readers read what the markers name, not every file of a partition
    export_logs([b.as_posix()], ExportOptions(out))
    finish(out)
    assert not stray.exists() and leftovers(out) == set()
    assert set(state(out)) == {"a.jsonl", "b.jsonl"}
    assert "part-0123" not in (out / "views.sql").read_text(encoding="utf-8")


# -- writers take turns -----------------------------------------------------------------------------------------


def test_a_second_writer_waits_and_is_told_who_holds_the_dataset(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    log = jsonl(tmp_path / "a.jsonl")
    told: list[str] = []
    done = threading.Event()

    def second() -> None:
        export_logs([log.as_posix()], ExportOptions(out), on_wait=told.append)
        done.set()

    with writers_lock(out):
        worker = threading.Thread(target=second, daemon=True)
        worker.start()
        assert not done.wait(1.0)  # it waits while the first holds the dataset
        assert told and f"pid {os.getpid()}" in told[0]
        assert not (out / "logs").exists()
    assert done.wait(60)
    worker.join(60)
    assert state(out) == {"a.jsonl": (4, 0, 0)}
    assert (out / LOCK_FILE).is_file()


def test_two_concurrent_exports_end_with_every_log_once(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    logs, params = flights
    logs.append(jsonl(tmp_path / "logs" / "b.jsonl"))
    out = tmp_path / "ds"
    command = [sys.executable, "-m", "codegen", "export", "-q", "-o", str(out), *map(str, logs)]
    runs = [subprocess.Popen([*command, *extra], stderr=subprocess.PIPE) for extra in ([], ["--failsafe", str(params)])]
    for proc in runs:
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err.decode()
    reference = tmp_path / "ref"
    assert main(["export", "-q", "-o", str(reference), *map(str, logs)]) == 0
    got, want = state(out), state(reference)
    assert {s: v[0] for s, v in got.items()} == {s: v[0] for s, v in want.items()}  # every log once
    assert leftovers(out) == set() and len(list((out / "logs").glob("*.json"))) == 3


# -- kill -9 at file-system steps -------------------------------------------------------------------------------

# Runs battgen export, counting its file-system steps (each rename, fsync, delete and folder made), and
# kills itself with SIGKILL just before step N (0: never); prints the count on stderr when it lives.
DRIVER = """
import os, shutil, signal, sys
stop, count = int(sys.argv[1]), [0]
# only the dataset's steps count: the user's IR cache (written on a miss) must not shift the numbering
dataset = os.path.abspath(sys.argv[sys.argv.index("-o") + 1])
def step(fn, by_path):
    def wrapped(*args, **kwargs):
        inside = kwargs.get("dir_fd") is not None  # shutil.rmtree's steps within a tree it removes
        if by_path and not inside and not os.path.abspath(os.fspath(args[0])).startswith(dataset):
            return fn(*args, **kwargs)
        count[0] += 1
        if count[0] == stop:
            os.kill(os.getpid(), signal.SIGKILL)
        return fn(*args, **kwargs)
    return wrapped
for name in ("replace", "rename", "fsync", "unlink", "rmdir", "mkdir"):
    setattr(os, name, step(getattr(os, name), name != "fsync"))
from codegen.cli.main import main
code = main(sys.argv[2:])
print(f"STEPS {count[0]}", file=sys.stderr)
sys.exit(code)
"""
MAX_KILLS = 6  # kills per run in the suite; BATTGEN_CRASH_ALL=1 tries every step
SEED = 32


def _driver(tmp_path: Path, stop: int, args: list[str]) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "crash_driver.py"
    script.write_text(DRIVER, encoding="utf-8")
    return subprocess.run(
        [sys.executable, str(script), str(stop), *args], capture_output=True, text=True, timeout=300, check=False
    )


def test_kill_at_file_system_steps_leaves_the_old_or_the_new_state(
    tmp_path: Path, flights: tuple[list[Path], Path]
) -> None:
    logs, params = flights
    new_log = jsonl(tmp_path / "logs" / "b.jsonl")
    base = tmp_path / "base"
    assert main(["export", "-q", "-o", str(base), *map(str, logs)]) == 0  # the old state: two logs, no replay
    old = state(base)
    run = ["export", "-q", "-o", "{out}", *map(str, logs), str(new_log), "--failsafe", str(params)]
    counted = tmp_path / "counted"
    _copy(base, counted)
    done = _driver(tmp_path, 0, [a.format(out=counted) for a in run])
    assert done.returncode == 0, done.stderr
    new = state(counted)  # the new state: three logs, replayed
    steps = int(done.stderr.rsplit("STEPS ", 1)[1])
    assert new.keys() == old.keys() | {"b.jsonl"} and steps > 10
    chosen = range(1, steps + 1) if os.environ.get("BATTGEN_CRASH_ALL") else _sample(steps)
    for stop in chosen:
        out = tmp_path / f"kill-{stop}"
        _copy(base, out)
        killed = _driver(tmp_path, stop, [a.format(out=out) for a in run])
        assert killed.returncode == -9, f"step {stop}: {killed.stderr}"
        seen = state(out)
        for source, value in seen.items():  # each log whole: its old version or its new one
            assert value in (old.get(source), new[source]), f"step {stop}: {source} reads {value}"
        assert old.keys() <= seen.keys(), f"step {stop}: a log was lost"
        assert main(["export", "-q", "-o", str(out), *run[4:]]) == 0  # the next run completes it
        assert state(out) == new and leftovers(out) == set(), f"step {stop}"


def _sample(steps: int) -> list[int]:
    """A few steps of a run, chosen the same way every time: the first, the last and some between."""
    between = random.Random(SEED).sample(range(2, steps), k=min(MAX_KILLS - 2, steps - 2))
    return sorted({1, steps, *between})


def _copy(src: Path, dst: Path) -> None:
    shutil.copytree(src, dst)


def test_an_output_that_is_a_file_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "ds"
    target.write_text("mine\n", encoding="utf-8")
    assert main(["export", "-q", "-o", str(target), str(jsonl(tmp_path / "a.jsonl"))]) == 2
    err = capsys.readouterr().err
    assert err == f"battgen: -o {target}: is a file; expected a folder for the dataset\n"
    assert target.read_text(encoding="utf-8") == "mine\n"


def _as_before_versions(out: Path) -> None:
    """The dataset as battgen wrote it before versions: fixed file names, markers naming no files."""
    for path in (out / "logs").glob("*.json"):
        manifest = json.loads(path.read_text())
        for rel in (f for files in manifest.pop("files").values() for f in files):
            stem = Path(rel).name.split("-", 1)[0]
            (out / rel).rename((out / rel).with_name("part-0.parquet" if stem == "part" else f"{stem}.parquet"))
        del manifest["version"]
        path.write_text(json.dumps(manifest), encoding="utf-8")


def test_a_dataset_from_before_versions_reads_and_reexports(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    logs, params = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "--raw", "-o", str(out), *map(str, logs), "--failsafe", str(params)]) == 0
    want = state(out)
    _as_before_versions(out)
    legacy = {f for f in all_files(out) if f.endswith(".parquet")}
    assert any(f.endswith("/part-0.parquet") for f in legacy) and any(f.endswith("/events.parquet") for f in legacy)
    assert state(out) == want and leftovers(out) == set()  # read as they are, nothing taken for a leftover
    (params.parent / "other.param").write_text(params.read_text().replace("10.5", "10.8"), encoding="utf-8")
    assert (
        main(
            ["export", "-q", "--raw", "-o", str(out), *map(str, logs), "--failsafe", str(params.parent / "other.param")]
        )
        == 0
    )
    assert {s: v[0] for s, v in state(out).items()} == {s: v[0] for s, v in want.items()}
    assert not legacy & all_files(out) and leftovers(out) == set()  # the old names went with the swap


# -- markers that cannot be trusted ------------------------------------------------------------------------------


def _marker_path(out: Path, source: str) -> Path:
    (path,) = [p for p in (out / "logs").glob("*.json") if json.loads(p.read_text())["source"] == source]
    return path


def test_a_marker_naming_files_outside_its_tables_deletes_nothing_there(
    tmp_path: Path, flights: tuple[list[Path], Path]
) -> None:
    """A marker is what the next run deletes: one naming a file outside the dataset's tables (a hand edit, a crafted
    dataset) counts as no marker, so the re-export replaces it and the named file stays."""
    logs, _ = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), str(logs[0])]) == 0
    victim = tmp_path / "victim.parquet"
    victim.write_bytes(b"keep me")
    path = _marker_path(out, "flight.tlog")
    data = json.loads(path.read_text())
    data["files"]["battery"].append("../victim.parquet")
    path.write_text(json.dumps(data))
    assert main(["export", "-q", "-o", str(out), str(logs[0])]) == 0  # exported again: the marker is no marker
    assert victim.read_bytes() == b"keep me"
    assert set(state(out)) == {"flight.tlog"}
    assert "../victim.parquet" not in path.read_text()


def test_a_marker_naming_a_missing_file_is_exported_again(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    """Found by the commit fuzzer: a marker whose file name was damaged made the run say "already in the dataset"
    while the views read a file that is not there."""
    logs, _ = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), str(logs[0])]) == 0
    path = _marker_path(out, "flight.tlog")
    data = json.loads(path.read_text())
    data["files"]["battery"] = [name.replace(".parquet", "-x.parquet") for name in data["files"]["battery"]]
    path.write_text(json.dumps(data))
    assert main(["export", "-q", "-o", str(out), str(logs[0])]) == 0
    assert set(state(out)) == {"flight.tlog"}  # the query reads every named file: none is missing


def test_a_marker_replacing_another_sources_log_hides_nothing(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    """``replaces`` hides an earlier export of the same, grown, source: a marker naming another source's log
    (damaged or crafted) must not hide that flight, nor have the next run delete it."""
    logs, _ = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), *map(str, logs)]) == 0
    before = state(out)
    bin_log = json.loads(_marker_path(out, "flight.bin").read_text())["log"]
    path = _marker_path(out, "flight.tlog")
    data = json.loads(path.read_text())
    data["replaces"] = bin_log
    path.write_text(json.dumps(data))
    assert state(out) == before
    assert main(["export", "-q", "-o", str(out), *map(str, logs)]) == 0
    assert state(out) == before


def test_a_log_id_of_digits_only_stays_text_in_the_views(tmp_path: Path, flights: tuple[list[Path], Path]) -> None:
    """A content id is hex: one in 20,000 is digits only, and DuckDB's hive partitioning would read ``log=<id>`` as
    a BIGINT, which then clashed with the file's own ``log`` text (a CI run's CAN export failed so). The views type
    the partition's ``log`` as text."""
    logs, _ = flights
    out = tmp_path / "ds"
    assert main(["export", "-q", "-o", str(out), str(logs[0])]) == 0
    path = _marker_path(out, "flight.tlog")
    data = json.loads(path.read_text())
    old, new = data["log"], "1234567890123456"
    for table in ("battery", "raw", "failsafe"):
        for folder in sorted((out / table).rglob(f"log={old}")):
            folder.rename(folder.with_name(f"log={new}"))
    text = path.read_text().replace(old, new)
    path.unlink()
    (out / "logs" / f"{new}.json").write_text(text)
    finish(out)
    rows = run_query(out, "SELECT DISTINCT typeof(log), log FROM battery").rows
    assert rows == [("VARCHAR", new)]
    assert run_query(out, "SELECT count(*) FROM flights").rows[0][0] >= 1
