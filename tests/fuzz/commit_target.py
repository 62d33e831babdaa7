"""The fuzz target of the export's commit path: a dataset whose metadata (``dataset.json``, a log's marker) holds
any bytes, exported onto again.

The commit protocol reads what earlier runs wrote: the dataset's layout, the markers naming each log's committed
version and tables. A file damaged on disk (a full disk, a hand edit, another tool) must give one clear line and
exit 1 or 2, or be repaired by the run -- never a traceback, and never a dataset that then reads wrong: after a
run that says it succeeded, the views read every log once.
"""

from __future__ import annotations

import functools
import shutil
import tempfile
from pathlib import Path

from targets import MASKED, MAX_MESSAGE, SEEDS, run_main

from codegen.apps.export.manifest import committed
from codegen.apps.export.query import run_query

LOG = SEEDS / "flight.tlog"


@functools.cache
def _template() -> Path:
    """A dataset holding the seed tlog, exported once per process (kept until the process ends)."""
    folder = Path(tempfile.mkdtemp(prefix="battgen-fuzz-commit-"))
    code, _, err = run_main(["export", "-q", "-o", str(folder / "ds"), str(LOG)])
    assert code == 0, err
    return folder / "ds"


def _metadata(dataset: Path) -> list[Path]:
    """The files of a dataset that the commit protocol reads back, in a stable order."""
    return [dataset / "dataset.json", *sorted((dataset / "logs").glob("*.json"))]


def seeds() -> list[bytes]:
    """Each metadata file of the template as written, after one byte choosing it (see :func:`commit`)."""
    return [bytes([i]) + p.read_bytes() for i, p in enumerate(_metadata(_template()))]


def commit(data: bytes) -> None:
    """The template with one metadata file replaced by ``data[1:]`` (``data[0]`` chooses which), exported onto
    with the same log again."""
    with tempfile.TemporaryDirectory(prefix="battgen-fuzz-") as folder:
        dataset = Path(folder) / "ds"
        shutil.copytree(_template(), dataset)
        files = _metadata(dataset)
        if data:
            files[data[0] % len(files)].write_bytes(data[1:])
        code, stdout, stderr = run_main(["export", "-q", "-o", str(dataset), str(LOG)])
        assert code in (0, 1, 2), (code, stderr[-2000:])
        assert "Traceback" not in stderr and not MASKED.search(stdout + stderr), stderr[-2000:]
        assert all(len(line) <= MAX_MESSAGE for line in stderr.splitlines())
        if code == 2:
            assert stderr.strip(), "exit 2 without a word"
        if code == 0:  # said to succeed: the log is in the views exactly once
            assert committed(dataset)["battery"], "a run that succeeded left no battery table"
            (sources,) = run_query(dataset, "SELECT count(DISTINCT log) FROM battery").rows
            assert sources == (1,), sources
