"""The crate's battery failsafe (`battgen::failsafe`, hand-written support code) against battgen's Python
evaluator: the random armed streams the evaluator is tested on (tests/failsafe_streams.py), on every vehicle,
with the seed's variants and the fallback chains' situations, give identical events -- time, battery, level,
cause, action code and name, whether it ran, the vehicle's outcome, priority, the values compared, and
ArduPilot's STATUSTEXT -- sample by sample. A changed event in the data fails the replay."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from rust_crate import Crate, cargo, shared_crate
from rust_failsafe_cases import DISTANCE, SEED_CRITICAL, VARIANTS

needs_cargo = pytest.mark.skipif(shutil.which("cargo") is None, reason="cargo not installed")
TEST = "failsafe_streams_give_pythons_events"


@pytest.fixture(scope="module")
def crate(tmp_path_factory: pytest.TempPathFactory) -> Crate:
    return shared_crate(tmp_path_factory)


def test_the_streams_reach_every_branch(crate: Crate) -> None:
    """The data is worth replaying: events of both levels and every cause, actions run and refused, disarms,
    every variant."""
    lines = [line for s in crate.streams for line in s.lines if line.startswith("event ")]
    assert len(lines) > 100
    words = [line.split("|")[0].split(" ") for line in lines]
    assert {w[3] for w in words} == {"low", "critical"}
    assert {w[4] for w in words} == {"voltage", "capacity", "distance"}
    outcomes = {w[7] for w in words}
    assert len(outcomes) >= 5 and {"not_run", "disarm", "none", "rtl"} <= outcomes, outcomes
    assert {w[13] for w in words} == {"raw", "resting"}
    assert {s.variants for s in crate.streams} == set(VARIANTS)
    assert any(s.events for s in crate.streams if SEED_CRITICAL in s.variants and DISTANCE not in s.variants)


@needs_cargo
def test_cargo_replays_pythons_failsafe_events(crate: Crate) -> None:
    done = cargo(crate, "test", "--offline", "--test", "failsafe_replay", "--", "--nocapture")
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    assert f"test {TEST} ... ok" in done.stdout
    m = re.search(r"failsafe replay: (\d+) streams, (\d+) events", done.stdout)
    assert m is not None, done.stdout[-2000:]
    assert (int(m.group(1)), int(m.group(2))) == (len(crate.streams), sum(s.events for s in crate.streams))


@needs_cargo
def test_a_changed_event_fails_the_replay(crate: Crate, tmp_path: Path) -> None:
    """The harness compares: one event's action code off by one, and the replay fails on that case."""
    text = (crate.root / "tests" / "failsafe_streams.txt").read_text(encoding="utf-8")
    changed = re.sub(r"^(event (?:\S+ ){4})(\d+)", lambda m: m.group(1) + str(int(m.group(2)) + 1), text,
                     count=1, flags=re.M)  # fmt: skip
    assert changed != text
    path = tmp_path / "streams.txt"
    path.write_text(changed, encoding="utf-8")
    done = cargo(crate, "test", "--offline", "--test", "failsafe_replay", env={"BATTGEN_FAILSAFE_STREAMS": str(path)})
    assert done.returncode != 0
    assert "case ending on line" in done.stdout + done.stderr
