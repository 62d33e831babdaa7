"""Fuzzing the export's commit path: a dataset whose ``dataset.json`` or a log's marker holds mutated bytes,
exported onto again, ends in one clear line or a dataset that reads every log once (tests/fuzz/commit_target.py).
And the long run's seeded mode (tests/fuzz/long_run.py ``--inputs``) runs every reader target: a few inputs each.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from budget import crashers, fuzz_settings
from commit_target import commit, seeds
from fuzz_inputs import mutated
from hypothesis import given
from hypothesis import strategies as st
from long_run import READERS, fuzz_inputs


@fuzz_settings(ci=15)
@given(st.data())
def test_fuzz_commit_path(data: st.DataObject) -> None:
    commit(data.draw(st.one_of(mutated(seeds()), st.binary(max_size=64))))


def test_the_long_run_tries_every_reader_target(tmp_path: Path) -> None:
    assert {"commit", "view-ulog", "view-dataflash", "view-tlog", "view-jsonl", "read-dts", "read-params"} <= set(
        READERS
    )
    for target in READERS:
        tried, found, _ = fuzz_inputs(target, 3 if target != "commit" else 1, seed=1, save=tmp_path)
        assert tried >= 1 and found == [], (target, found)


@pytest.mark.parametrize("path", crashers("commit"), ids=lambda p: p.name)
def test_commit_crashers_replay(path: Path) -> None:
    """Metadata the long run once found mishandled: a marker naming a missing or misnamed file, files under a
    damaged key, a dataset.json nested past the parser or with a key misspelt."""
    commit(path.read_bytes())
