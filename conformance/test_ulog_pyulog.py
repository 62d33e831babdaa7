"""Our ULog writer and reader against pyulog, the reference reader of PX4 logs.

- pyulog reads the logs we write (random BatteryStatus / BatteryStatusV0 instances, several
  instances per topic, nested messages) with our field names, order, types and values;
- our reader gives pyulog's values for every topic of two real PX4 logs, and for logs pyulog writes;
- the real logs' battery_status predates message versioning: the difference from our schema is
  pinned, and every field that matches decodes to pyulog's value (the others keep their defaults).
"""

from __future__ import annotations

import importlib
import io
import struct
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pyulog import ULog
from shared_data import REAL_LOGS, missing
from ulog_values import instances

from codegen.backends.python.writer import generate
from codegen.frontends import uorb
from generated import _ulog
from generated.uorb import BatteryStatus, BatteryStatusV0

DATA = REAL_LOGS
LOGS = ("sample_log_small.ulg", "sample_px4_events.ulg")


def expected_column(values: list[Any]) -> np.ndarray[Any, Any]:
    return np.array([np.float32(v) if isinstance(v, float) else v for v in values])


def pyulog_fields(cls: type[Any]) -> list[tuple[str, int, str]]:
    return [(m.ctype, m.count, m.name) for m in cls.ulog_format().members]


def data_of(ulog: ULog) -> dict[tuple[str, int], dict[str, Any]]:
    return {(d.name, d.multi_id): d.data for d in ulog.data_list}


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(st.one_of(instances(BatteryStatus), instances(BatteryStatusV0)), st.integers(0, 3)),
        min_size=1,
        max_size=12,
    )
)
def test_pyulog_reads_the_logs_we_write(records: list[tuple[Any, int]]) -> None:
    out = io.BytesIO()
    info = {"sys_name": "battgen", "ver_hw": "TEST", "time_ref_utc": -3600}
    params = {"BAT1_N_CELLS": 4, "BAT1_V_CHARGED": 4.2}
    with _ulog.Writer(
        out, timestamp=123456, info=info, parameters=params, messages=[BatteryStatus, BatteryStatusV0]
    ) as w:
        for msg, multi_id in records:
            w.write(msg, multi_id=multi_id)
    raw = out.getvalue()
    ulog = ULog(io.BytesIO(raw))
    assert not ulog.file_corruption and ulog.start_timestamp == 123456
    assert ulog.msg_info_dict == info and ulog.initial_parameters["BAT1_N_CELLS"] == 4
    assert ulog.initial_parameters["BAT1_V_CHARGED"] == np.float32(4.2)
    for cls in (BatteryStatus, BatteryStatusV0):
        assert ulog.message_formats[cls.UORB_TOPICS[0]].fields == pyulog_fields(cls)
    got = data_of(ulog)
    wanted: dict[tuple[str, int], list[Any]] = {}
    for msg, multi_id in records:
        wanted.setdefault((type(msg).UORB_TOPICS[0], multi_id), []).append(msg)
    assert set(got) == set(wanted)
    for key, msgs in wanted.items():
        columns = type(msgs[0]).decode_batch(b"".join(m.encode() for m in msgs), use_numpy=False)
        assert list(got[key]) == list(columns)  # same names in the same order: PX4's layout
        for name, values in columns.items():
            assert np.array_equal(got[key][name], expected_column(values), equal_nan=True), (key, name)
        ours = _ulog.read(raw).columns(key[0], key[1], use_numpy=True)
        for name, column in ours.items():
            assert np.array_equal(column.astype(got[key][name].dtype), got[key][name], equal_nan=True), name


@pytest.fixture(scope="module")
def nested(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ModuleType]:
    root = tmp_path_factory.mktemp("nested")
    (root / "msg").mkdir()
    (root / "msg" / "Cell.msg").write_text("uint64 timestamp\nfloat32 v\nchar[6] label\nbool ok\n", encoding="utf-8")
    (root / "msg" / "Pack.msg").write_text("uint64 timestamp\nCell[3] cells\nCell spare\nuint8 n\n", encoding="utf-8")
    generate(uorb.parse_dir(root / "msg"), root / "ulog_nested_pkg")
    sys.path.insert(0, str(root))
    try:
        yield importlib.import_module("ulog_nested_pkg.uorb")
    finally:
        sys.path.remove(str(root))
        for name in [m for m in sys.modules if m.startswith("ulog_nested_pkg")]:
            del sys.modules[name]


def test_pyulog_flattens_our_nested_formats_like_our_columns(nested: ModuleType) -> None:
    packs = []
    for i in range(5):
        p = nested.Pack(timestamp=i, n=i * 3)
        for k, cell in enumerate(p.cells):
            cell.v, cell.label, cell.ok = i + k / 8, f"c{k}{i}", bool((i + k) % 2)
        p.spare.label = "spare"
        packs.append(p)
    out = io.BytesIO()
    nested._ulog.write(out, packs)
    ulog = ULog(io.BytesIO(out.getvalue()))
    assert ulog.message_formats["cell"].fields == [
        (m.ctype, m.count, m.name) for m in nested.Cell.ulog_format().members
    ]
    theirs = ulog.get_dataset("pack").data
    ours = nested._ulog.read(out.getvalue()).columns("pack", use_numpy=True)
    compare_columns(ours, theirs)
    assert theirs["cells[2].label[1]"].tolist() == [ord("2")] * 5 and theirs["spare.ok"].tolist() == [0] * 5


def compare_columns(ours: dict[str, Any], theirs: dict[str, Any]) -> int:
    """Assert our columns equal pyulog's (char arrays split per char, padding skipped); count them."""
    names = {n for n in theirs if not n.split(".")[-1].startswith("_padding")}
    compared = 0
    for name, column in ours.items():
        if column.dtype.kind == "S":  # one bytes column for char[N]; pyulog has one int8 column per char
            width = column.dtype.itemsize
            chars = np.frombuffer(column.astype(f"S{width}").tobytes(), dtype=np.int8).reshape(-1, width)
            for i in range(width):
                assert np.array_equal(chars[:, i], theirs[f"{name}[{i}]"]), f"{name}[{i}]"
                names.discard(f"{name}[{i}]")
        else:
            assert np.array_equal(column.astype(theirs[name].dtype), theirs[name], equal_nan=True), name
            names.discard(name)
        compared += 1
    assert not names, f"pyulog has columns we lack: {sorted(names)[:5]}"
    return compared


@pytest.fixture(scope="module", params=LOGS)
def real_log(request: pytest.FixtureRequest) -> tuple[str, ULog, _ulog.Log]:
    path = DATA / request.param
    if not path.is_file():
        missing(f"test log {request.param}")
    return request.param, ULog(str(path)), _ulog.read(path)


def test_every_topic_of_the_real_logs_reads_as_pyulog_reads_it(real_log: tuple[str, ULog, _ulog.Log]) -> None:
    _, ulog, ours = real_log
    theirs = data_of(ulog)
    assert set(ours.topics()) == set(theirs) and len(theirs) > 50
    compared = 0
    for (topic, multi_id), data in theirs.items():
        compared += compare_columns(ours.columns(topic, multi_id, use_numpy=True), data)
    assert compared > 1000 and not ours.warnings
    # the stdlib path gives the same values
    lists = ours.columns("vehicle_status", 0, use_numpy=False)
    assert lists["timestamp"] == theirs[("vehicle_status", 0)]["timestamp"].tolist()
    assert ours.info == ulog.msg_info_dict and ours.parameters == ulog.initial_parameters
    assert [(k, v) for _, k, v in ulog.changed_parameters] == ours.changed_parameters
    assert [(m.log_level, m.timestamp, m.message) for m in ulog.logged_messages] == ours.logged
    assert [d.duration for d in ulog.dropouts] == ours.dropouts
    assert ours.info_multiple == ulog.msg_info_multiple_dict
    assert {n: f.fields for n, f in ulog.message_formats.items()} == {
        n: [(m.ctype, m.count, m.name) for m in f.members] for n, f in ours.formats.items()
    }


def test_we_read_the_logs_pyulog_writes(real_log: tuple[str, ULog, _ulog.Log], tmp_path: Path) -> None:
    name, ulog, _ = real_log
    ulog.write_ulog(str(tmp_path / name))
    ours = _ulog.read(tmp_path / name)
    for d in ulog.data_list:
        compare_columns(ours.columns(d.name, d.multi_id, use_numpy=True), d.data)


# The real logs' battery_status against our BatteryStatus (MESSAGE_VERSION 1).
PINNED = {
    "sample_log_small.ulg": {
        "missing": [
            "time_remaining_s", "full_charge_capacity_wh", "remaining_capacity_wh",
            "nominal_voltage", "internal_resistance_estimate", "ocv_estimate", "ocv_estimate_filtered",
            "volt_based_soc_estimate", "voltage_prediction", "prediction_error", "estimation_covariance_norm",
            "manufacture_date", "interface_error", "faults", "over_discharge_count", "is_required",
        ],
        "extra": [
            "voltage_filtered_v", "current_filtered_a", "run_time_to_empty", "serial_number",
        ],
        "renamed": [["average_current_a", "current_average_a"]],
        "converted": [["voltage_cell_v", "float[14]", "float[10]"], ["cell_count", "uint8_t", "int32_t"]],
    },
    "sample_px4_events.ulg": {
        "missing": [
            "internal_resistance_estimate", "ocv_estimate", "ocv_estimate_filtered", "volt_based_soc_estimate",
            "voltage_prediction", "prediction_error", "estimation_covariance_norm",
        ],
        "extra": [
            "voltage_filtered_v", "current_filtered_a", "custom_faults", "average_power", "available_energy",
            "design_capacity", "serial_number", "average_time_to_full", "mode",
        ],
        "renamed": [],
        "converted": [],
    },
}  # fmt: skip


def test_battery_status_difference_is_pinned(real_log: tuple[str, ULog, _ulog.Log]) -> None:
    name, _, ours = real_log
    diff = ours.compare(BatteryStatus).to_dict()
    assert [n for n, _ in diff["missing"]] == PINNED[name]["missing"]
    assert [n for n, _ in diff["extra"]] == PINNED[name]["extra"]
    assert diff["renamed"] == PINNED[name]["renamed"] and diff["converted"] == PINNED[name]["converted"]
    assert diff["retyped"] == [] and not diff["identical"]
    text = str(ours.compare(BatteryStatus))
    assert text.startswith("battery_status: the log's format differs from the schema (battery_status)\n")
    assert "  only in the log (kept as extras): voltage_filtered_v float, current_filtered_a float" in text
    if name == "sample_log_small.ulg":
        assert text.endswith(
            "  converted (range-checked): voltage_cell_v (schema float[14], log float[10]), "
            "cell_count (schema uint8_t, log int32_t)"
        )
    # V0 has serial_number: one fewer extra field against either log
    v0 = ours.compare(BatteryStatusV0, topic="battery_status")
    assert [n for n, _ in v0.extra] == [n for n in PINNED[name]["extra"] if n != "serial_number"]


def test_battery_status_fields_the_log_lacks_keep_their_defaults(real_log: tuple[str, ULog, _ulog.Log]) -> None:
    """What the log has is compared value by value in test_ulog_px4_versions.py; what it lacks
    is the schema's default (its sentinel where it has one), never a made-up value."""
    _, _, ours = real_log
    diff = ours.compare(BatteryStatus)
    defaults = BatteryStatus()
    records = BatteryStatus.from_ulog(ours)
    assert records
    for name, _ in diff.missing:
        default = getattr(defaults, name)
        values = [getattr(r.instance, name) for r in records]
        assert all(v == default or (v != v and default != default) for v in values), name


def test_appended_data_reads_as_pyulog_reads_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fmt = BatteryStatus.ulog_format().renamed("battery_status").text().encode()

    def rec(kind: str, body: bytes) -> bytes:
        return struct.pack("<HB", len(body), ord(kind)) + body

    def data(ts: int) -> bytes:
        return rec("D", b"\0\0" + BatteryStatus(timestamp=ts, voltage_v=ts / 2).encode()[:166])

    body = rec("F", fmt) + rec("A", b"\0\0\0battery_status") + data(1) + data(2) + data(3)[:40]
    start = 16 + 43 + len(body)
    flags = bytes(8) + bytes((_ulog.INCOMPAT_DATA_APPENDED,)) + bytes(7) + struct.pack("<3Q", start, 0, 0)
    raw = _ulog.MAGIC + b"\x01" + bytes(8) + rec("B", flags) + body + data(4) + data(5)
    (tmp_path / "appended.ulg").write_bytes(raw)
    theirs = ULog(str(tmp_path / "appended.ulg")).get_dataset("battery_status").data
    assert "no subscription found for message id 0" in capsys.readouterr().out
    with pytest.warns(_ulog.ULogWarning, match="before an appended-data offset"):
        ours = _ulog.read(tmp_path / "appended.ulg")
    # Both drop the record cut at the offset. pyulog then closes its subscriptions, so it ignores
    # the appended records ("no subscription found"); we keep them: a subscription lasts the file.
    assert theirs["timestamp"].tolist() == [1, 2]
    columns = ours.columns("battery_status", use_numpy=True)
    assert columns["timestamp"].tolist() == [1, 2, 4, 5] and columns["voltage_v"].tolist() == [0.5, 1, 2, 2.5]
    compare_columns({name: column[:2] for name, column in columns.items()}, theirs)
