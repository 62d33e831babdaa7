"""The C-speed record index (codegen/inputs/ulog/index.py) against the generated walker it stands in
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
from shared_data import real_logs

from codegen.inputs.ulog import columns as ulog_columns
from codegen.inputs.ulog import index as ulog_index
from generated import _ulog
from generated._ulog_parse import WALK_STATE
from generated.uorb import BatteryInfo, BatteryStatus

REAL_LOGS = real_logs()


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


def _columns_both_ways(data: bytes, tmp: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every field of every battery_status chunk, by the compiled gather and by numpy: the same bytes."""
    path = tmp / "log.ulg"
    path.write_bytes(data)
    gathered: list[bytes] = []
    for compiled in (True, False):
        if not compiled:
            monkeypatch.setattr(ulog_columns, "gather", None)
        with ulog_columns.UlogColumns(path, path.name, BatteryStatus) as log:
            for chunk in log.instances(chunk=64):
                gathered += [chunk.columns[name].tobytes() for name in sorted(chunk.columns)]
    half = len(gathered) // 2
    assert half and gathered[:half] == gathered[half:]


@pytest.mark.parametrize("path", REAL_LOGS, ids=lambda p: p.name)
def test_the_compiled_gather_reads_what_numpy_reads(
    path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    if ulog_columns.gather is None:
        pytest.skip("the C extension is not built")
    _columns_both_ways(path.read_bytes(), tmp_path, monkeypatch)


def test_the_compiled_gather_on_a_written_log(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    if ulog_columns.gather is None:
        pytest.skip("the C extension is not built")
    _columns_both_ways(_battery_log(300), tmp_path, monkeypatch)


def test_the_compiled_gather_refuses_to_read_outside() -> None:
    gather = ulog_columns.gather
    if gather is None:
        pytest.skip("the C extension is not built")
    data, out = bytes(range(64)), bytearray(8)
    gather(data, np.array([0, 16], np.int64), 8, [(4, 4, out)])
    assert bytes(out) == bytes([4, 5, 6, 7, 20, 21, 22, 23])
    with pytest.raises(ValueError, match="outside the buffer"):
        gather(data, np.array([0, 60], np.int64), 8, [(4, 4, out)])  # a record running past the end
    with pytest.raises(ValueError, match="outside the buffer"):
        gather(data, np.array([-1], np.int64), 8, [(0, 4, out)])
    with pytest.raises(ValueError, match="outside the record"):
        gather(data, np.array([0], np.int64), 8, [(6, 4, out)])  # a field past the record's end
    with pytest.raises(ValueError, match="too small"):
        gather(data, np.array([0, 8, 16], np.int64), 8, [(0, 4, out)])  # 3 records, room for 2
