"""A log that another program rewrites while battgen reads it: reported as changed, never a SIGBUS.

The readers map ULog (ours) and DataFlash (pymavlink's) files; truncating a mapped file kills the
reader with SIGBUS. While a read lease holds the file the truncating program waits, this process
is told (SIGIO) and the read ends with FileChanged; the writer then goes on.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from codegen.apps.battery import readers
from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.export.engine import ExportOptions, export_logs
from codegen.inputs.files.held import FileChanged, held
from tests.shared_data import REAL_LOGS, require

_TRUNCATE = "import os, sys; os.truncate(sys.argv[1], 64)"


def _truncator(path: Path) -> subprocess.Popen[bytes]:
    """Another program truncating ``path`` in place (an uploader rewriting it)."""
    return subprocess.Popen([sys.executable, "-c", _TRUNCATE, str(path)])


def _wait_for_signal(seconds: float = 20.0) -> None:
    """Sleep while the lease break reaches this process (FileChanged is raised from the sleep)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        time.sleep(0.01)
    pytest.fail("no FileChanged within the time: the lease did not hold the file")


@pytest.fixture
def log_copy(tmp_path: Path) -> Path:
    source = require(REAL_LOGS / "sample_log_small.ulg")
    copy = tmp_path / "flight.ulg"
    shutil.copyfile(source, copy)
    return copy


def _leases_work(path: Path) -> bool:
    with held(path, path.name) as hold:
        return hold.leased


def test_a_held_file_makes_its_writer_wait_and_the_reader_stop(log_copy: Path) -> None:
    if not _leases_work(log_copy):
        pytest.skip("this file system gives no leases: readers read whole files instead")
    size = log_copy.stat().st_size
    with pytest.raises(FileChanged, match="changed while it was read"):
        with held(log_copy, "flight.ulg"):
            writer = _truncator(log_copy)
            _wait_for_signal()
    assert writer.wait(timeout=30) == 0  # the writer went on once the hold was let go
    assert log_copy.stat().st_size == 64 < size


def test_a_log_truncated_during_export_fails_alone(
    log_copy: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The export of a log rewritten while it is read: that log reported, nothing of it in the dataset,
    the other log of the run exported (no SIGBUS, no traceback)."""
    if not _leases_work(log_copy):
        pytest.skip("this file system gives no leases")
    other = tmp_path / "other.ulg"
    shutil.copyfile(require(REAL_LOGS / "sample_px4_events.ulg"), other)
    original = readers.ulog_batches
    writers: list[subprocess.Popen[bytes]] = []

    def truncated_midway(path: Path, *args: object) -> Iterator[object]:
        for i, batch in enumerate(original(path, *args)):  # type: ignore[arg-type]
            yield batch
            if i == 0 and path == log_copy:
                writers.append(_truncator(path))
                _wait_for_signal()

    monkeypatch.setattr(readers, "ulog_batches", truncated_midway)
    out = tmp_path / "dataset"
    results = export_logs([str(log_copy), str(other)], ExportOptions(out=out))
    by_path = {Path(r.path).name: r for r in results}
    assert by_path["flight.ulg"].status == "failed"
    assert "changed while it was read" in by_path["flight.ulg"].error
    assert by_path["other.ulg"].status == "exported" and by_path["other.ulg"].rows > 0
    assert writers and writers[0].wait(timeout=30) == 0
    exported = [p.name for p in out.rglob("*.parquet")]
    assert exported and not any(by_path["flight.ulg"].log and by_path["flight.ulg"].log in p for p in exported)


def test_an_unheld_log_is_read_whole_and_a_truncation_cannot_crash(log_copy: Path) -> None:
    """A file open for writing elsewhere gets no lease: the ULog is read into memory, so truncating it
    under the reader changes nothing of what is read."""
    catalog = bundled_catalog()
    expected = sum(b.n for b in readers.read_log(log_copy, "flight.ulg", catalog))
    with log_copy.open("r+b") as writer:  # a writer holds it open: no lease can be had
        with held(log_copy, "flight.ulg") as hold:
            assert not hold.leased
        batches = readers.read_log(log_copy, "flight.ulg", catalog)
        first = next(batches)
        writer.truncate(64)
        writer.flush()
        assert first.n + sum(b.n for b in batches) == expected
