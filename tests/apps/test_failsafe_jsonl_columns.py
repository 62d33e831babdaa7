"""A JSON Lines stream replayed over its columns (``battgen failsafe STREAM.jsonl``) gives exactly the per-sample
evaluator's events (the oracle): on the random streams of tests/failsafe_streams.py, on every real log's samples
written as a stream, and on streams the columns must refuse (then read sample by sample, with the same errors)."""

from __future__ import annotations

import json
import math
import tempfile
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from failsafe_streams import ROW, VALUES, Row, timed
from hypothesis import given, settings
from hypothesis import strategies as st
from test_failsafe_columnar import _logs, _parameter_sets, _table

from codegen.apps.failsafe.evaluator import make_failsafe
from codegen.apps.failsafe.jsonl_columns import read_sample_columns
from codegen.apps.failsafe.settings import battery_settings
from codegen.apps.failsafe.stream import Reader, Replay, open_reader
from codegen.apps.failsafe.vehicles import VEHICLES
from codegen.errors import BattgenError


@cache
def _reader() -> Reader:
    return open_reader(None)


def _number(x: float) -> float | None:
    return None if math.isnan(x) else x


def _lines(rows: list[Row]) -> str:
    """The rows as a stream as a program writes it: one shape, null where a value is unknown."""
    out = []
    for t, b, v, i, m, a in rows:
        battery = {"voltage_v": _number(v), "current_a": _number(i), "consumed_mah": _number(m)}
        out.append(json.dumps({"t": t, "armed": a == 1.0, "instance": b + 1, "battery": battery}))
    return "".join(line + "\n" for line in out)


def _run(path: Path, values: dict[str, float], vehicle: str, variants: tuple[str, ...], per_sample: bool) -> Any:
    v = VEHICLES[vehicle]
    fs = make_failsafe(battery_settings(values, v), v, variants=variants)
    replay = Replay(fs, _reader())
    try:
        samples = _reader().read(path) if per_sample else None
        events = list(replay.run(path, "x", samples))
    except BattgenError as exc:
        return str(exc)
    return events, replay.samples, {i: m.failsafe for i, m in fs.monitors.items()}


def _same(text: str, values: dict[str, float], vehicle: str, variants: tuple[str, ...] = (), plain: bool = True) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.jsonl"
        path.write_text(text, encoding="utf-8")
        assert (read_sample_columns(path) is not None) is plain
        expected = _run(path, values, vehicle, variants, per_sample=True)
        got = _run(path, values, vehicle, variants, per_sample=False)
    assert got == expected
    return 0 if isinstance(expected, str) else len(expected[0])


@settings(max_examples=200)
@given(st.lists(ROW, min_size=1, max_size=60), VALUES, st.sampled_from(["copter", "rover", "plane"]), st.booleans())
def test_random_streams_give_the_oracles_events(rows: list[Any], values: dict[str, float], vehicle: str,
                                                seed: bool) -> None:  # fmt: skip
    _same(_lines(timed(rows)), values, vehicle, ("seed-critical",) if seed else ())


def test_real_logs_as_streams_give_the_oracles_events() -> None:
    fired = replayed = 0
    for path in _logs():
        table = _table(path)
        if table is None:
            continue
        t, battery, volts, amps, mah, armed, _ = table.sorted_columns()
        if not 0 < len(t) <= 20_000:
            continue  # the oracle reads every line with json; the large logs add time, not cases
        rows = list(zip(*(c.tolist() for c in (t, battery, volts, amps, mah, armed)), strict=True))
        text = _lines(rows)
        for values in _parameter_sets(table)[:3]:
            fired += _same(text, values, "copter")
            replayed += 1
    assert replayed > 10 and fired > 5  # the threshold sets do fire


VALUES_FIRING = {"BATT_LOW_VOLT": 12.0, "BATT_CRT_VOLT": 11.0, "BATT_LOW_TIMER": 1, "BATT_FS_LOW_ACT": 2}
GOOD = '{"t": 0.5, "armed": true, "battery": {"voltage_v": 11.5, "current_a": 3}}\n'


@pytest.mark.parametrize(
    "line",
    [
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 01, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": +1, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1., "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": .5, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1e5.3, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1e5e3, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": --1, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1-1, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1e, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": NaN, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": true, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": , "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 1 2, "current_a": 3}}',
        '{"t": 2.0, "armed": null, "battery": {"voltage_v": 11, "current_a": 3}}',
        '{"t": null, "armed": true, "battery": {"voltage_v": 11, "current_a": 3}}',
        '{"t": 1e999, "armed": true, "battery": {"voltage_v": 11, "current_a": 3}}',
        '{"armed": true, "t": 2.0, "battery": {"voltage_v": 11, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 11, "current_a": 3}, "home_set": false}',
        '{"t": 2.0,  "armed": true, "battery": {"voltage_v": 11, "current_a": 3}}',
        '{"t": 2.0, "armed": true, "battery": {"voltage_v": 11, "current_a": 3}}\r',
        "",
        "# a comment",
        "[1, 2]",
    ],
)
def test_other_lines_are_read_sample_by_sample(line: str) -> None:
    text = GOOD + '{"t": 1.0, "armed": true, "battery": {"voltage_v": 11.2, "current_a": 3}}\n' + line + "\n"
    text += '{"t": 3.0, "armed": true, "battery": {"voltage_v": 10.0, "current_a": 3}}\n'
    _same(text, VALUES_FIRING, "copter", plain=False)


@pytest.mark.parametrize(
    "text",
    [
        GOOD + '{"t": 2, "armed": false, "battery": {"voltage_v": 1e1, "current_a": -0.0}}',  # no final newline
        '{"t": 0, "armed": true, "instance": 2, "battery": {"voltage_v": null, "consumed_mah": 10}}\n'
        '{"t": 5, "armed": true, "instance": 16, "battery": {"voltage_v": 10.5, "consumed_mah": -1.5E+2}}\n',
        '{"battery": {"current_a": 1}, "armed": false, "t": 0.0}\n'
        '{"battery": {"current_a": 2}, "armed": true, "t": 9}\n',
    ],
)
def test_plain_streams_of_any_key_order(text: str) -> None:
    _same(text, VALUES_FIRING | {"BATT_CAPACITY": 100, "BATT_LOW_MAH": 50}, "copter")


def test_a_time_going_back_is_the_evaluators_error() -> None:
    text = GOOD + '{"t": 0.1, "armed": true, "battery": {"voltage_v": 11, "current_a": 3}}\n'
    _same(text, VALUES_FIRING, "copter")  # read as columns, replayed sample by sample: the error at its line


def test_an_instance_that_is_not_a_whole_number_is_the_readers_error() -> None:
    text = GOOD + '{"t": 1, "armed": true, "instance": 2, "battery": {"voltage_v": 1}}\n'
    text += '{"t": 2, "armed": true, "instance": 2.0, "battery": {"voltage_v": 1}}\n'
    _same(text, VALUES_FIRING, "copter", plain=False)
    columns = read_sample_columns  # a first line with instance 17 is refused too
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.jsonl"
        path.write_text('{"t": 1, "armed": true, "instance": 17, "battery": {"voltage_v": 1}}\n', encoding="utf-8")
        assert columns(path) is None
        path.write_text('{"t": 1, "armed": true, "instance": 3, "battery": {"voltage_v": 1}}\n', encoding="utf-8")
        got = columns(path)
        assert got is not None and got.instance.tolist() == [3] and np.isnan(got.current).all()
