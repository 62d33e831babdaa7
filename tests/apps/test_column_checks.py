"""The report's validation over the battery view's columns gives the per-record read's findings exactly.

The oracle is the old second read (:func:`codegen.apps.report.series._record_input`: the ULog/tlog record reader
and the generated ``validate()`` record by record), on every real ULog and tlog of ``../shared``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import ROOT
from hypothesis import given, settings
from hypothesis import strategies as st
from shared_data import SHARED

from codegen.apps.battery.column_checks import (
    column_finding_groups,
    column_findings,
    flaggable,
    group_findings,
    row_instance,
)
from codegen.apps.battery.columns import NDArray
from codegen.apps.battery.view import read_view
from codegen.apps.gate.validate import make_checker
from codegen.apps.report.series import _record_input, read_input
from codegen.inputs.records import Record

SCHEMAS = ROOT / "schemas"


def _logs(pattern: str) -> list[Path]:
    found = sorted(SHARED.rglob(pattern)) if SHARED.is_dir() else []
    if not found and os.environ.get("CI"):
        pytest.fail(f"no {pattern} under {SHARED}: the real logs are missing")
    return found


ULOGS = _logs("*.ulg")
TLOGS = _logs("*.tlog")


def _name(path: Path) -> str:
    return path.relative_to(SHARED).as_posix()


@pytest.mark.parametrize("path", ULOGS, ids=_name)
def test_ulog_findings_from_columns_equal_the_record_read(path: Path) -> None:
    name = path.as_posix()
    old = _record_input(path, SCHEMAS, name, None, "ulog")
    _, checker = make_checker(SCHEMAS, "uorb.BatteryStatus", [name], "ulog")
    new = column_findings(path, name, "ulog", read_view(path, name, all_fields=True), checker)
    assert new is not None, "every real ULog of ../shared is placed from the columns"
    assert group_findings(new.findings) == old.findings  # the report keeps its findings as groups
    assert new.notices == old.notices
    assert new.unreadable == old.unreadable
    report = read_input(path, SCHEMAS)  # and the report takes them
    assert (report.findings, report.notices, report.unreadable) == (old.findings, old.notices, old.unreadable)


@pytest.mark.parametrize("path", ULOGS, ids=_name)
def test_ulog_finding_groups_equal_the_grouped_findings(path: Path) -> None:
    """The report's groups, counted over the columns, are the per-record findings grouped: counts, the first of
    each group (record index, t, message), the notices."""
    name = path.as_posix()
    _, checker = make_checker(SCHEMAS, "uorb.BatteryStatus", [name], "ulog")
    chunks = list(read_view(path, name, all_fields=True))
    exact = column_findings(path, name, "ulog", chunks, checker)
    grouped = column_finding_groups(path, name, "ulog", chunks, checker)
    assert exact is not None and grouped is not None
    assert grouped == (group_findings(exact.findings), exact.notices, exact.unreadable)


def test_real_ulogs_have_findings_placed_as_the_reader_places_them() -> None:
    """Not an empty comparison: the real PX4 logs carry findings, each with its ULog location."""
    located = [f for path in ULOGS for _, _, f in column_findings_of(path)]
    if not ULOGS:
        pytest.skip("../shared is missing")
    assert located
    assert all(set(f.location or {}) == {"topic", "multi_id", "timestamp_us", "offset"} for f in located)


def column_findings_of(path: Path) -> list[Any]:
    _, checker = make_checker(SCHEMAS, "uorb.BatteryStatus", [path.as_posix()], "ulog")
    out = column_findings(path, path.as_posix(), "ulog", read_view(path, all_fields=True), checker)
    assert out is not None
    return out.findings


@pytest.mark.parametrize("path", TLOGS, ids=_name)
def test_tlog_report_findings_equal_the_record_read(path: Path) -> None:
    """A tlog keeps the second read (its batch lacks the frames' places): the report still equals it."""
    name = path.as_posix()
    old = _record_input(path, SCHEMAS, name, None, "tlog")
    report = read_input(path, SCHEMAS)
    assert (report.findings, report.notices, report.unreadable) == (old.findings, old.notices, old.unreadable)


# -- synthetic columns ---------------------------------------------------------------------------

_MESSAGE, _CHECKER = make_checker(SCHEMAS, "uorb.BatteryStatus", [], "ulog")
_CLASS: Any = _CHECKER.cls
_FLOATS = st.one_of(
    st.sampled_from([0.0, -1.0, math.nan, math.inf, -math.inf, 1e39, -3.5, 0.5, 1.0, 2.0, 255.0]),
    st.floats(allow_nan=True, allow_infinity=True, width=32),
)


# a record the validator passes where nothing is drawn (the class's default max_error, 0, is below its minimum)
_VALID = {"max_error": 1}


def _columns(rows: list[dict[str, Any]]) -> dict[str, NDArray]:
    """The columns the view gives a ULog of the bundled layout: every field, defaults where not drawn."""
    default = _CLASS()
    out: dict[str, NDArray] = {}
    for f in _MESSAGE.fields:
        if f.is_padding:
            continue
        base = getattr(default, f.name)
        values = [row.get(f.name, _VALID.get(f.name, base)) for row in rows]
        if isinstance(base, list):
            out[f.name] = np.array(values, np.float32 if base and isinstance(base[0], float) else np.int64)
        elif isinstance(base, bool):
            out[f.name] = np.array(values, np.bool_)
        elif isinstance(base, float):
            out[f.name] = np.array(values, np.float32)
        else:
            out[f.name] = np.array(values, np.uint64 if f.name == "timestamp" else np.int64)
    return out


# a record's drawn fields: values in and out of every check's range, sentinels, NaN and the infinities
_ROW_FIELDS = {
    "voltage_v": _FLOATS,
    "current_a": _FLOATS,
    "remaining": _FLOATS,
    "temperature": _FLOATS,
    "max_error": st.one_of(st.sampled_from([0, 1, 50, 100, 101]), st.integers(0, 65535)),
    "cell_count": st.one_of(st.sampled_from([0, 4, 6, 14, 15]), st.integers(0, 255)),
    "warning": st.integers(0, 255),
    "voltage_cell_v": st.lists(_FLOATS, min_size=14, max_size=14),
}


@settings(max_examples=30)
@given(
    st.lists(
        st.fixed_dictionaries(
            {},
            optional={
                **_ROW_FIELDS,
                "scale": _FLOATS,
                "remaining_capacity_wh": _FLOATS,
                "timestamp": st.integers(0, 2**64 - 1),
            },
        ),
        min_size=1,
        max_size=8,
    )
)
def test_rows_outside_the_mask_have_no_findings_and_rows_inside_are_the_oracles(rows: list[dict[str, Any]]) -> None:
    with np.errstate(over="ignore"):  # a drawn 1e39 is inf in a float32 log
        columns = _columns(rows)
        rows = [_as_floats32(row) for row in rows]
    mask = flaggable(_CHECKER, columns, len(rows))
    for k, row in enumerate(rows):
        expected = _CHECKER.check(Record(k, 0, None, "x", instance=_CLASS(**{**_VALID, **row})))
        built = row_instance(_CHECKER.cls, _MESSAGE, columns, k)
        got = _CHECKER.check(Record(k, 0, None, "x", instance=built))
        assert repr(got) == repr(expected)  # repr: a NaN value is not equal to itself
        if not mask[k]:
            assert expected == []
    valid = _columns([{}] * 3)
    assert not flaggable(_CHECKER, valid, 3).any()  # a valid record is not judged one by one


def _as_floats32(row: dict[str, Any]) -> dict[str, Any]:
    """The drawn values as a float32 log holds them (the per-record decoder's values)."""
    out: dict[str, Any] = {}
    for key, value in row.items():
        if isinstance(value, float):
            out[key] = float(np.float32(value))
        elif isinstance(value, list):
            out[key] = [float(np.float32(v)) for v in value]
        else:
            out[key] = value
    return out


@pytest.mark.parametrize("keep", [0.5, 0.9])
def test_a_truncated_real_ulog_reports_what_the_record_read_does(tmp_path: Path, keep: float) -> None:
    """Damage (a log cut mid-record): the findings and notices are still the per-record read's."""
    source = SHARED / "data" / "ulog" / "sample_px4_events.ulg"
    if not source.is_file():
        pytest.skip("../shared is missing")
    data = source.read_bytes()
    path = tmp_path / "cut.ulg"
    path.write_bytes(data[: int(len(data) * keep)])
    old = _record_input(path, SCHEMAS, path.as_posix(), None, "ulog")
    report = read_input(path, SCHEMAS)
    assert old.records > 0
    assert repr((report.findings, report.notices, report.unreadable)) == repr(
        (old.findings, old.notices, old.unreadable)
    )


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.fixed_dictionaries({}, optional=_ROW_FIELDS), min_size=1, max_size=12),
    st.integers(0, 1),
)
def test_groups_of_a_written_log_equal_its_grouped_findings(rows: list[dict[str, Any]], instances: int) -> None:
    """Drawn records (two battery instances at most) written as a ULog: the groups counted over the columns are
    the per-record findings grouped, whatever fields they flag."""
    import tempfile

    from generated import _ulog_writer

    with np.errstate(over="ignore"):
        records = [
            (_CLASS(**{**_VALID, **_as_floats32(row), "timestamp": 1000 * (k + 1)}), k % (instances + 1))
            for k, row in enumerate(rows)
        ]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "drawn.ulg"
        _ulog_writer.write(path, records)
        name = path.as_posix()
        chunks = list(read_view(path, name, all_fields=True))
        exact = column_findings(path, name, "ulog", chunks, _CHECKER)
        grouped = column_finding_groups(path, name, "ulog", chunks, _CHECKER)
        assert exact is not None and grouped is not None
        assert repr(grouped) == repr((group_findings(exact.findings), exact.notices, exact.unreadable))
