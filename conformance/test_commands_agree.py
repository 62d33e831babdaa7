"""One log, one set of numbers: every real log of ``../shared`` through ``report --format json``, ``export`` and the
DuckDB ``flights`` view, the failsafe's samples, ``validate`` and ``convert --to concepts`` (every kind whose records
have a message schema), and, for PX4 ULogs, pyulog on the same file.

Per battery: the record count, the first and last ``t`` (seconds since the log's start), the minimum and maximum
pack voltage, the peak current, the charge and energy used and the armed time. The report and the view are two
spellings of one definition (:mod:`codegen.apps.battery.figures`: numpy and SQL), so they agree to rounding; the
failsafe's samples carry a float32 reading as its shortest decimal (as the firmware's comparison sees it), so its
voltages and currents agree to float32 precision. The references for the other kinds are their own conformance
tests on the same files (``test_tlog_batches_pymavlink.py``, ``test_dataflash_pymavlink.py``).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from shared_data import SHARED, missing

from codegen.apps.battery.figures import FlightFigures, flight_figures
from codegen.apps.failsafe.logs import log_samples
from codegen.apps.schemas.messages import BATTERY_MESSAGES
from codegen.cli.main import main
from codegen.errors import BattgenError
from codegen.inputs.files.kinds import detect

duckdb = pytest.importorskip("duckdb")
pyulog = pytest.importorskip("pyulog")

BATTERY_KINDS = ("ulog", "tlog", "dataflash", "can")
FIGURES = ("records", "first_t", "last_t", "min_voltage", "max_voltage", "max_current", "charge_used", "energy_used")
REL = 1e-9  # numpy and SQL sum in other orders
FLOAT32 = 1e-6  # the failsafe's shortest-decimal float32 readings


def _real_logs() -> list[Path]:
    """Every log or capture under ../shared, each content once (the corpora share files)."""
    seen: set[str] = set()
    out = []
    for path in sorted(SHARED.joinpath("data").rglob("*")) + sorted(SHARED.joinpath("corpus").rglob("*")):
        if not path.is_file() or "upstream" in path.parts or path.stat().st_size == 0:
            continue
        try:
            kind = detect(path)
        except OSError:
            continue
        if kind not in BATTERY_KINDS:
            continue
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        if digest not in seen:
            seen.add(digest)
            out.append(path)
    assert len({p.name for p in out}) == len(out), "the flights view tells logs apart by their names"
    return out


LOGS = _real_logs() if SHARED.is_dir() else []


def _close(a: float | None, b: float | None, rel: float) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return math.isclose(a, b, rel_tol=rel, abs_tol=1e-9)


def _agree(mine: dict[str, Any], other: dict[str, Any], rel: float, what: str) -> None:
    for key in FIGURES:
        if key in other:
            assert _close(mine[key], other[key], rel), f"{what}: {key} {mine[key]} != {other[key]}"


def _report(path: Path, tmp: Path, capsys: pytest.CaptureFixture[str]) -> dict[int, dict[str, Any]] | None:
    out = tmp / "report.json"
    code = main(["report", "--format", "json", "-o", str(out), str(path)])
    capsys.readouterr()
    if code != 0:
        return None
    doc = json.loads(out.read_text())
    batteries = doc["inputs"][0]["batteries"]
    return {b["battery"]: b["flight"] | {"serial": b["serial"], "message": b["message"]} for b in batteries}


def _failsafe(path: Path) -> tuple[dict[int, FlightFigures], bool]:
    """The figures of the samples the failsafe replays, per battery (0-based, as the report numbers them)."""
    try:
        table = log_samples(path)
    except BattgenError:  # a capture without frames: the failsafe exits 2 saying so
        return {}, False
    rows: dict[int, list[tuple[float, float, float, float, float]]] = {}
    for s in table.samples():
        r = s.battery
        rows.setdefault(s.instance - 1, []).append(
            (
                s.t,
                math.nan if r.voltage_v is None else r.voltage_v,
                math.nan if r.current_a is None else r.current_a,
                math.nan if r.consumed_mah is None else r.consumed_mah * 3.6,
                1.0 if s.armed else 0.0,
            )
        )
    out = {}
    for battery, values in rows.items():
        t, v, i, c, armed = (np.array(col, np.float64) for col in zip(*values, strict=True))
        out[battery] = flight_figures(t, v, i, c, np.full(len(t), np.nan), armed)
    return out, table.has_arming


def _pyulog(path: Path) -> list[tuple[int, float, float, float | None, float | None, float | None]]:
    """pyulog's battery_status instances: count, first and last t, voltage extremes and peak current, with the
    schema's sentinels (voltage_v 0, current_a -1) as unknown."""
    log = pyulog.ULog(str(path), ["battery_status"])
    out = []
    for d in log.data_list:
        t = (d.data["timestamp"].astype(np.int64) - log.start_timestamp) / 1e6
        v = d.data["voltage_v"].astype(np.float64)
        i = d.data["current_a"].astype(np.float64)
        v, i = v[(v != 0) & ~np.isnan(v)], i[(i != -1) & ~np.isnan(i)]
        out.append(
            (
                len(t),
                float(t.min()),
                float(t.max()),
                float(v.min()) if len(v) else None,
                float(v.max()) if len(v) else None,
                float(i.max()) if len(i) else None,
            )
        )
    return sorted(out, key=lambda x: (x[0], x[1]))


@pytest.fixture(scope="module")
def flights(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[int, dict[str, Any]]]:
    """Every real log exported in one run, and the ``flights`` view per log source and battery."""
    if not LOGS:
        missing("the real logs of ../shared")
    out = tmp_path_factory.mktemp("dataset")
    code = main(["export", "-q", "-o", str(out), *map(str, LOGS)])
    assert code in (0, 1)  # 1: some captures hold no battery records
    con = duckdb.connect()
    con.execute(f"SET file_search_path = '{out}'")  # views.sql names the dataset's files relative to it
    con.execute((out / "views.sql").read_text())
    names = [c for c in FIGURES if c != "max_current"] + ["peak_current", "duration_armed"]
    rows = con.execute(f"SELECT source, battery, {', '.join(names)} FROM flights").fetchall()
    view: dict[str, dict[int, dict[str, Any]]] = {}
    for source, battery, *values in rows:
        fig = dict(zip(names, values, strict=True))
        fig["max_current"], fig["armed_s"] = fig.pop("peak_current"), fig.pop("duration_armed")
        view.setdefault(source, {})[int(battery)] = fig  # source: the file's name (unique among the real logs)
    return view


def _ids(paths: list[Path]) -> Iterator[str]:
    for p in paths:
        yield f"{p.parent.name}/{p.name}"


@pytest.mark.parametrize("path", LOGS, ids=list(_ids(LOGS)))
def test_every_command_reads_the_same_flight(
    path: Path,
    flights: dict[str, dict[int, dict[str, Any]]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    report = _report(path, tmp_path, capsys)
    view = flights.get(path.name)
    if report is None:  # no battery records (most CAN captures): no command finds any
        assert view is None
        assert not _failsafe(path)[0]
        return
    assert view is not None and set(view) == set(report), f"batteries: report {sorted(report)}, view {view}"
    samples, has_arming = _failsafe(path)
    assert set(samples) == set(report)
    for battery, fig in report.items():
        _agree(fig, view[battery], REL, f"battery {battery}: report vs flights view")
        assert _close(fig["armed_s"], view[battery]["armed_s"], REL), "armed time: report vs flights view"
        replayed = samples[battery].__dict__
        _agree(fig, {k: replayed[k] for k in ("records", "first_t", "last_t")}, 0.0, "report vs failsafe samples")
        _agree(fig, {k: replayed[k] for k in ("min_voltage", "max_voltage", "max_current")}, FLOAT32, "failsafe")
        if has_arming:
            assert _close(fig["armed_s"], replayed["armed_s"], REL), "armed time: report vs failsafe"
        else:
            assert fig["armed_s"] is None
    kind = detect(path)
    if kind == "ulog":
        mine = sorted(
            ((f["records"], f["first_t"], f["last_t"], f["min_voltage"], f["max_voltage"], f["max_current"])
             for f in report.values()),
            key=lambda x: (x[0], x[1]),
        )  # fmt: skip
        reference = _pyulog(path)
        assert len(mine) == len(reference)
        for ours, theirs in zip(mine, reference, strict=True):
            assert ours[:3] == pytest.approx(theirs[:3], rel=0, abs=1e-9)
            for a, b in zip(ours[3:], theirs[3:], strict=True):
                assert _close(a, b, 0.0), f"vs pyulog: {ours} != {theirs}"
    messages = {f["message"] for f in report.values()}
    if kind in BATTERY_MESSAGES and len(messages) == 1:  # a tlog read from SYS_STATUS: its SYS_STATUS records
        _records_agree(path, messages.pop(), report, capsys)


def _records_agree(
    path: Path, message: str, report: dict[int, dict[str, Any]], capsys: pytest.CaptureFixture[str]
) -> None:
    """``validate`` counts the records the report read; ``convert --to concepts`` gives the same voltages and
    currents (its output carries no clock, so only the numbers are compared). For every kind whose records have a
    message schema (ULog, tlog, CAN captures; a DataFlash log's have none)."""
    main(["validate", "--format", "json", "--message", message, str(path)])
    doc = json.loads(capsys.readouterr().out)
    assert doc["files"][0]["records"] == sum(f["records"] for f in report.values())
    code = main(["convert", "--from", message, "--to", "concepts", "--out-format", "jsonl", str(path)])
    lines = capsys.readouterr().out.splitlines()
    assert code == 0 and len(lines) == doc["files"][0]["records"]
    records = [json.loads(line) for line in lines]
    volts = [r["pack_voltage"] for r in records if r["pack_voltage"] is not None]
    amps = [r["current"] for r in records if r["current"] is not None]

    def known(key: str) -> list[float]:
        return [f[key] for f in report.values() if f[key] is not None]

    assert _close(min(volts, default=None), min(known("min_voltage"), default=None), 0.0)
    assert _close(max(volts, default=None), max(known("max_voltage"), default=None), 0.0)
    assert _close(max(amps, default=None), max(known("max_current"), default=None), 0.0)
