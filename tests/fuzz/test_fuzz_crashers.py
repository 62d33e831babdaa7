"""Replaying the crasher corpus: every input in ``tests/fuzz/crashers/<target>/`` once crashed, hung or
blew up memory in that target (tests/fuzz/targets.py ``TARGETS``) and must now pass it, on every run.

To add one: save the input the fuzzer printed (``Falsifying example``) as a file in the target's folder,
named for what it broke.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from budget import CRASHERS, crashers
from targets import TARGETS

CASES = [(target, path) for target in sorted(TARGETS) for path in crashers(target)]


def test_every_crasher_folder_names_a_target() -> None:
    """Folders of these targets' kinds (the schema and CAN fuzzers replay their own folders)."""
    folders = sorted(p.name for p in CRASHERS.iterdir() if p.is_dir()) if CRASHERS.is_dir() else []
    ours = [f for f in folders if f.startswith(("decode-", "read-", "cli-"))]
    assert [f for f in ours if f not in TARGETS] == []
    assert CASES, "the corpus holds the reproducers of issue 10"


@pytest.mark.parametrize(("target", "path"), CASES, ids=[f"{t}/{p.name}" for t, p in CASES])
def test_crasher_replays_cleanly(target: str, path: Path) -> None:
    TARGETS[target](path.read_bytes())
