"""Logs of older PX4 releases read into today's BatteryStatus with no field silently lost.

PX4 changed battery_status many times (renamed ``average_current_a``, widened ``voltage_cell_v``
from float[10] to float[14], narrowed ``cell_count`` from int32 to uint8, dropped
``voltage_filtered_v``, ``run_time_to_empty``, ``serial_number``...). Logs are written here from
PX4's own old definitions (../shared/corpus/upstream/px4_battery_status_history/, see its SOURCE.md),
through a package our generator makes from each, and read back with the bundled
``BatteryStatus.from_ulog`` (releases 1.14 to 1.18 and main from ../shared/corpus/upstream/px4_msgs/ too);
pyulog, the reference reader, reads the same file. Every value pyulog
sees must be in the record: in the instance under its (renamed) field, or in the record's extras
-- the two real shared logs included, every battery instance of them.
"""

from __future__ import annotations

import dataclasses
import importlib
import io
import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyulog import ULog
from shared_data import REAL_LOGS, UPSTREAM, missing
from ulog_values import instances, scalar

from codegen.backends.python.writer import generate
from codegen.frontends import uorb
from generated import _ulog
from generated.uorb import BatteryStatus

ROOT = Path(__file__).resolve().parent.parent
CORPUS = UPSTREAM / "px4_battery_status_history"
# (package name, definition file): oldest first; the first predates the generated timestamp line
VERSIONS = {
    "px4_011d7193": CORPUS / "battery_status.011d7193.msg",
    "px4_log_v1_11": CORPUS / "battery_status.log_v1_11.msg",
    "px4_0a799f45": CORPUS / "BatteryStatus.0a799f45.msg",
    "px4_v0": ROOT / "schemas" / "uorb" / "BatteryStatusV0.msg",
}
# the releases h11px4's corpus holds (px4_msgs mirror of PX4's msg/, see its SOURCE.md)
PX4_MSGS = UPSTREAM / "px4_msgs"
VERSIONS |= {
    f"px4_{v.replace('.', '_')}": PX4_MSGS / v / "BatteryStatus.msg"
    for v in ("1.14", "1.15", "1.16", "1.17", "1.18", "main")
}
FIELDS = {f.name: f for f in dataclasses.fields(BatteryStatus)}
RENAMED = _ulog.RENAMED["battery_status"]


def _same(ours: Any, theirs: Any) -> bool:
    if isinstance(theirs, np.floating | float):
        a, b = float(ours), float(theirs)
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(theirs, np.bytes_ | bytes):
        return bytes(ours) == bytes(theirs)
    return int(ours) == int(theirs)


def assert_nothing_lost(ulog: ULog, records: list[_ulog.Record[BatteryStatus]], topic: str) -> int:
    """Every value pyulog reads for ``topic`` is in ``records``: the instance's field (under
    today's name, inside its array) or the record's extras. Returns the values compared."""
    compared = 0
    datasets = [d for d in ulog.data_list if d.name == topic]
    assert sorted(d.multi_id for d in datasets) == sorted({r.multi_id for r in records})
    for d in datasets:
        mine = [r for r in records if r.multi_id == d.multi_id]
        assert len(mine) == len(d.data["timestamp"]) > 0
        for column, values in d.data.items():
            head, bracket, rest = column.partition("[")
            index = int(rest[:-1]) if bracket else None
            name = RENAMED.get(head, head)
            for rec, theirs in zip(mine, values, strict=True):
                if column in rec.extras:
                    assert _same(rec.extras[column], theirs), (column, rec.extras[column], theirs)
                else:
                    assert name in FIELDS, f"{column}: neither in the instance nor in the extras"
                    ours = getattr(rec.instance, name)
                    if index is not None:
                        assert index < len(ours), column
                        ours = ours[index]
                    assert _same(ours, theirs), (column, ours, theirs)
                compared += 1
    return compared


@pytest.fixture(scope="module")
def old_packages(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, ModuleType]]:
    """A generated package per old definition, its class named BatteryStatus (topic battery_status)."""
    root = tmp_path_factory.mktemp("px4_versions")
    sys.path.insert(0, str(root))
    out = {}
    try:
        for name, path in VERSIONS.items():
            folder = root / f"{name}_msg"
            folder.mkdir()
            text = path.read_text(encoding="utf-8")
            if "uint64 timestamp" not in text:  # PX4's generator added it to such definitions then
                text = "uint64 timestamp\n" + text
            (folder / "BatteryStatus.msg").write_text(text, encoding="utf-8")
            generate(uorb.parse_dir(folder), root / name)
            out[name] = importlib.import_module(f"{name}.uorb")
        yield out
    finally:
        sys.path.remove(str(root))
        for mod in [m for m in sys.modules if m.split(".")[0] in VERSIONS]:
            del sys.modules[mod]


def _instances(cls: type[Any]) -> st.SearchStrategy[Any]:
    """As ulog_values.instances, but an int32 cell_count (the oldest layouts) is mostly a real cell count."""
    types = {f.name: f.metadata["type"] for f in dataclasses.fields(cls)}
    if types.get("cell_count") != "int32":
        return instances(cls)
    return instances(cls, {"cell_count": st.one_of(st.integers(0, 14), scalar("int32"))})


def _write(module: ModuleType, msgs: list[tuple[Any, int]]) -> bytes:
    out = io.BytesIO()
    module._ulog.write(out, msgs)
    return out.getvalue()


@pytest.mark.parametrize("version", list(VERSIONS))
def test_logs_of_old_px4_releases_lose_no_field(old_packages: dict[str, ModuleType], version: str) -> None:
    module = old_packages[version]
    cls = module.BatteryStatus
    checked = []

    @settings(settings.default, max_examples=15)
    @given(st.lists(st.tuples(_instances(cls), st.integers(0, 2)), min_size=1, max_size=6))
    def run(msgs: list[tuple[Any, int]]) -> None:
        raw = _write(module, msgs)
        log = _ulog.read(raw)
        records = BatteryStatus.from_ulog(log)
        assert [r.multi_id for r in records] == [m for _, m in msgs]  # every instance, in file order
        checked.append(assert_nothing_lost(ULog(io.BytesIO(raw)), records, "battery_status"))

    run()
    assert sum(checked) > 0


def test_what_each_old_release_maps_to(old_packages: dict[str, ModuleType]) -> None:
    """The mapping itself, from the old definitions: renamed, converted (range-checked), kept aside."""
    diffs = {}
    for version, module in old_packages.items():
        log = _ulog.read(_write(module, [(module.BatteryStatus(), 0)]))
        diffs[version] = log.compare(BatteryStatus)
    small = diffs["px4_log_v1_11"]
    assert small.renamed == (("average_current_a", "current_average_a"),)
    assert [(r.name, r.schema, r.log) for r in small.converted] == [
        ("voltage_cell_v", "float[14]", "float[10]"),
        ("cell_count", "uint8_t", "int32_t"),
    ]
    assert [n for n, _ in small.extra] == [
        "voltage_filtered_v", "current_filtered_a", "run_time_to_empty", "serial_number"
    ]  # fmt: skip
    assert [(r.name, r.log) for r in diffs["px4_011d7193"].converted] == [("cell_count", "int32_t")]
    assert not diffs["px4_0a799f45"].converted and not diffs["px4_0a799f45"].renamed
    assert [n for n, _ in diffs["px4_v0"].extra] == ["serial_number"] and not diffs["px4_v0"].retyped


def test_a_value_that_does_not_fit_stays_in_the_extras(old_packages: dict[str, ModuleType]) -> None:
    module = old_packages["px4_log_v1_11"]
    raw = _write(module, [(module.BatteryStatus(cell_count=300, voltage_cell_v=[3.9] * 10), 1)])
    (rec,) = BatteryStatus.from_ulog(raw)
    assert rec.multi_id == 1 and rec.unfit == ("cell_count",) and rec.extras["cell_count"] == 300
    assert rec.instance.cell_count == BatteryStatus().cell_count  # the default, not a wrapped 300 % 256
    assert rec.instance.voltage_cell_v[:11] == [pytest.approx(3.9)] * 10 + [0.0]


@pytest.mark.parametrize("name", ["sample_log_small.ulg", "sample_px4_events.ulg"])
def test_real_logs_every_instance_every_field(name: str) -> None:
    path = REAL_LOGS / name
    if not path.is_file():
        missing("the shared real PX4 logs")
    records = BatteryStatus.from_ulog(path)
    compared = assert_nothing_lost(ULog(str(path), ["battery_status"]), records, "battery_status")
    assert compared > 1000
    if name == "sample_log_small.ulg":  # two power modules: 6 cells of 3.90 V and 12 of 4.16 V
        first = {r.multi_id: r.instance for r in reversed(records)}
        assert first[0].cell_count == 6 and first[0].voltage_cell_v[5] == pytest.approx(3.9016, abs=1e-4)
        assert first[1].cell_count == 12 and first[1].voltage_cell_v[9] == pytest.approx(4.1576, abs=1e-4)


def test_validate_names_a_value_that_does_not_fit(
    old_packages: dict[str, ModuleType], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from codegen.cli.main import main

    module = old_packages["px4_log_v1_11"]
    path = tmp_path / "old.ulg"
    path.write_bytes(_write(module, [(module.BatteryStatus(cell_count=6, max_error=1, scale=1.0), 0),
                                     (module.BatteryStatus(cell_count=-3, max_error=1, scale=1.0), 1)]))  # fmt: skip
    code = main(["validate", "--message", "uorb.BatteryStatus", "--format", "json", str(path)])
    doc = json.loads(capsys.readouterr().out)
    (unfit,) = [n for n in doc["files"][0]["notices"] if n["kind"] == "unfit"]
    assert unfit["data"]["multi_id"] == 1 and unfit["data"]["fields"] == {"cell_count": -3}
    assert "does not fit the schema's type, left at its default: cell_count = -3" in unfit["message"]
    assert code == 0 and doc["files"][0]["records"] == 2
