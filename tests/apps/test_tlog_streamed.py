"""A large tlog is walked twice and its batteries handed out in chunks (flat memory): on every real tlog of the
corpus, the chunks hold exactly the records, clock, arming and context of the single walk."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from codegen.apps.battery import tlog_batches as tlog
from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.sources import Batch
from tests.shared_data import require, shared

TLOGS = sorted(
    p
    for folder in ("realworld2", "realworld3", "realworld3b")
    for p in (shared("corpus", folder, "tlog").glob("*.tlog") if shared("corpus", folder, "tlog").is_dir() else [])
)


def _by_battery(batches: list[Batch]) -> dict[tuple[str, int], list[Batch]]:
    out: dict[tuple[str, int], list[Batch]] = {}
    for b in batches:
        out.setdefault((str(b.vehicle), int(b.instance[0])), []).append(b)
    return out


def _joined(parts: list[Batch], get: str) -> np.ndarray:
    return np.concatenate([np.asarray(getattr(b, get)) for b in parts])


def test_the_corpus_has_tlogs() -> None:
    require(shared("corpus", "realworld3b", "tlog"))
    assert len(TLOGS) >= 3


@pytest.mark.parametrize("path", TLOGS, ids=[p.name for p in TLOGS])
def test_two_walks_give_the_single_walks_batches(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    catalog = bundled_catalog()
    once = list(tlog.tlog_batches(path, path.name, catalog))
    monkeypatch.setattr(tlog, "STREAM_ABOVE", 0)
    monkeypatch.setattr(tlog, "CHUNK", 7)
    twice = list(tlog.tlog_batches(path, path.name, catalog))
    assert sum(b.n for b in twice) == sum(b.n for b in once)
    assert all(b.n <= 7 for b in twice)
    single, chunked = _by_battery(once), _by_battery(twice)
    assert single.keys() == chunked.keys()
    for key, (whole,) in single.items():
        parts = chunked[key]
        assert all(p.message == whole.message and p.context == whole.context for p in parts)
        np.testing.assert_array_equal(_joined(parts, "t"), whole.t)
        np.testing.assert_array_equal(_joined(parts, "time_us"), whole.time_us)
        if whole.armed is not None:
            np.testing.assert_array_equal(_joined(parts, "armed"), whole.armed)
        for name, column in whole.columns.items():
            np.testing.assert_array_equal(np.concatenate([p.columns[name] for p in parts]), column, err_msg=name)
