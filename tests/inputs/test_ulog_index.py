"""The C-speed record index (codegen/inputs/ulog_index.py) against the generated walker it stands in
for: the same offsets for every topic instance and the same log state afterwards (subscriptions,
info, parameters, logged text, counts, warnings in order), on the shared real logs, on logs the
generated writer makes, and on those logs damaged every way hypothesis finds."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from codegen.inputs import ulog_index
from generated import _ulog
from generated._ulog_parse import WALK_STATE
from generated.uorb import BatteryInfo, BatteryStatus

REAL_LOGS = sorted(Path("/work/shared/data/ulog").glob("*.ulg")) or sorted(
    Path(__file__).resolve().parents[2].joinpath("..", "shared", "data", "ulog").glob("*.ulg")
)


def _state(log: Any) -> dict[str, Any]:
    """What a walk of the data section leaves in a log, comparable across two logs."""
    out: dict[str, Any] = {}
    for name in WALK_STATE:
        value = getattr(log, name)
        if name == "_streams":
            value = {k: s.total for k, s in value.items()}
        elif name == "_by_id":
            value = {k: (e[1], e[2]) for k, e in value.items()}
        elif name in ("_layouts", "_column_sets"):
            continue
        out[name] = value
    return out


def _compare(data: bytes) -> None:
    """Index ``data`` both ways; equal offsets and state (or the same error)."""
    try:
        reference = _ulog.read(data, index=True, warn=False)
    except ValueError:  # not a log at all (its header): refused before any index is made
        with pytest.raises(ValueError):
            ulog_index.record_offsets(_ulog.read(data, index=False, warn=False))
        return
    expected = {k: s.offsets for k, s in reference._streams.items() if s.offsets}
    log = _ulog.read(data, index=False, warn=False)
    got = ulog_index.record_offsets(log)
    assert sorted(got) == sorted(expected)
    for key, offsets in expected.items():
        assert got[key].dtype == np.int64
        assert got[key].tolist() == offsets, key
    assert _state(log) == _state(reference)
    assert log.topics() == reference.topics()
    again = ulog_index.record_offsets(log)  # a log walked already: walked afresh, the same again
    assert {k: v.tolist() for k, v in again.items()} == {k: v.tolist() for k, v in got.items()}
    assert _state(log) == _state(reference)


def _battery_log(records: int, extra_topic: bool = True) -> bytes:
    """A log of battery_status records (two instances) interleaved with logged text and a second
    topic, written by the generated writer."""
    import io

    buf = io.BytesIO()
    with _ulog.Writer(buf, timestamp=1_000, info={"sys_name": "test"}, messages=(BatteryStatus, BatteryInfo)) as w:
        for i in range(records):
            msg = BatteryStatus(timestamp=2_000 + i, voltage_v=16.0 - i * 0.01, connected=True)
            w.write(msg, multi_id=i % 2)
            if extra_topic and i % 7 == 3:
                w.log(f"note {i}", level=6, timestamp=2_000 + i)
                w.write(BatteryInfo(timestamp=2_000 + i, id=i % 3), multi_id=0)
    return buf.getvalue()


def test_the_c_walk_is_built_where_ci_runs() -> None:
    """CI installs with a compiler: the compiled walk must be there, or these tests test nothing."""
    if os.environ.get("CI"):
        assert ulog_index.compiled()


@pytest.mark.parametrize("path", REAL_LOGS, ids=lambda p: p.name)
def test_real_logs(path: Path) -> None:
    _compare(path.read_bytes())


def test_written_log() -> None:
    _compare(_battery_log(300))


def test_fallback_gives_the_generated_index() -> None:
    data = _battery_log(50)
    log = _ulog.read(data, index=False, warn=False)
    got = ulog_index.record_offsets(log, use_compiled=False)
    reference = _ulog.read(data, index=True, warn=False)
    assert {k: v.tolist() for k, v in got.items()} == {k: s.offsets for k, s in reference._streams.items() if s.offsets}


def test_data_without_a_subscription_is_left_to_the_generated_walker() -> None:
    """A data record for a msg_id nobody subscribed: skipped and warned, as generated (the index
    hands such a log to the generated walker whole)."""
    data = bytearray(_battery_log(20, extra_topic=False))
    log = _ulog.read(bytes(data), index=True, warn=False)
    first = min(s.offsets[0] for s in log._streams.values() if s.offsets) - 5  # a 'D' record's start
    data[first + 3 : first + 5] = (999).to_bytes(2, "little")
    _compare(bytes(data))
    damaged = _ulog.read(bytes(data), index=False, warn=False)
    ulog_index.record_offsets(damaged)
    assert damaged.skipped_records == 1 and "msg_id 999" in " ".join(damaged.warnings)


_SMALL = _battery_log(120)


@settings(max_examples=60, deadline=None)
@given(
    cuts=st.lists(st.tuples(st.integers(0, len(_SMALL) - 1), st.binary(max_size=8)), max_size=4),
    end=st.integers(len(_SMALL) // 2, len(_SMALL)),
)
def test_damaged_logs(cuts: list[tuple[int, bytes]], end: int) -> None:
    """Bytes overwritten anywhere (headers, sizes, msg_ids, payloads) and the file cut short."""
    data = bytearray(_SMALL[:end])
    for at, patch in cuts:
        data[at : at + len(patch)] = patch
    _compare(bytes(data))


@settings(max_examples=20, deadline=None)
@given(at=st.integers(0, len(_SMALL) - 1), garbage=st.binary(min_size=1, max_size=64))
def test_inserted_garbage(at: int, garbage: bytes) -> None:
    """Bytes inserted: the chain is broken and resynchronised as the generated walker does."""
    _compare(_SMALL[:at] + garbage + _SMALL[at:])
