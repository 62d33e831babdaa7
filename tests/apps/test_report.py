"""``battgen report`` without a browser: the figures against the physics of a known flight, the decimation, the
page's self-containment, PNG output, and clear errors.

The synthetic flights (``flight_logs.py``) are built from a pack model with a known internal resistance and a
known current profile, so the figures are checked against those quantities, not against our own output.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from flight_logs import CELLS, RESISTANCE, write_capture_flight, write_flight

from codegen.apps.battery.figures import trapezoid
from codegen.apps.report.downsample import POINT_BUDGET, decimate, planned_length
from codegen.apps.report.figures import compute
from codegen.apps.report.series import read_input
from codegen.apps.schemas.package import bundled_schemas
from codegen.cli.main import main

pytest.importorskip("plotly")


@pytest.fixture(scope="module")
def flight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_flight(tmp_path_factory.mktemp("report") / "flight.ulg", seconds=300, hz=10, packs=2)


def test_every_battery_instance_is_read(flight: Path) -> None:
    item = read_input(flight, bundled_schemas())
    assert [(b.battery, len(b.t)) for b in item.batteries] == [(0, 3000), (1, 3000)]
    assert all(b.cell_count == CELLS for b in item.batteries)
    assert item.findings == []  # the synthetic records are valid


def test_internal_resistance_from_load_steps_is_the_packs(flight: Path) -> None:
    item = read_input(flight, bundled_schemas())
    for battery, ohms in zip(item.batteries, RESISTANCE, strict=True):
        f = compute(battery)
        assert f.internal_resistance_ohm == pytest.approx(ohms, rel=0.03)
        assert f.sag_per_amp_v_per_a == pytest.approx(ohms, rel=0.03)
        # a step every 30 s for 300 s: 9, less the three cruise-to-hover steps (7 A) under 20 % of the 42 A peak
        assert f.load_steps == 6


def test_charge_and_energy_used(flight: Path) -> None:
    item = read_input(flight, bundled_schemas())
    b = item.batteries[0]
    f = compute(b)
    # the counter the log carries, and the integral of the current it logged, agree
    amp_hours = trapezoid(np.array(b.t), np.array([np.nan if i is None else i for i in b.current]))
    assert amp_hours is not None
    assert f.charge_used_mah == pytest.approx(amp_hours / 3.6, rel=0.01)
    assert f.energy_used_wh is not None and f.average_power_w is not None
    assert f.energy_used_wh == pytest.approx(f.average_power_w * f.duration_s / 3600, rel=1e-9)
    assert f.peak_current_a == pytest.approx(42.0)
    assert f.time_below_s == {}
    below = compute(b, {"BATT_LOW_VOLT": 30.0})  # above the whole flight: all of it is below
    assert below.time_below_s["BATT_LOW_VOLT"] == pytest.approx(f.duration_s, rel=1e-6)


def test_decimation_keeps_every_peak() -> None:
    t = [k * 0.1 for k in range(36000)]
    v = [20.0 + (5.0 if k == 12345 else 0.0) - (3.0 if k == 30001 else 0.0) for k in range(36000)]
    xs, ys = decimate(t, v)
    assert len(xs) == planned_length(36000) == POINT_BUDGET
    assert max(y for y in ys if y is not None) == 25.0 and min(y for y in ys if y is not None) == 17.0
    assert xs == sorted(xs)
    small_t, small_v = decimate(t[:50], v[:50])
    assert small_t == t[:50] and small_v == v[:50]


def test_page_is_self_contained(tmp_path: Path, flight: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "r.html"
    assert main(["report", str(flight), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    # no script, style or image from anywhere else: the page opens offline
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=\"(https?:)?//", text)
    data = json.loads(re.search(r'<script id="figures" type="application/json">(.*?)</script>', text, re.S)[1])
    assert set(data) == {"plot-0", "plot-1"}
    assert "wrote" in capsys.readouterr().out


def test_capture_and_fleet(tmp_path: Path) -> None:
    logs = [write_capture_flight(tmp_path / f"c{k}.log", seconds=20, health=90 - k) for k in range(2)]
    out = tmp_path / "fleet.html"
    assert main(["report", *map(str, logs), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert 'id="flights"' in text and "pack 777" in text


def test_png_images(tmp_path: Path, flight: Path) -> None:
    pytest.importorskip("matplotlib")
    folder = tmp_path / "images"
    assert main(["report", str(flight), "--format", "png", "-o", str(folder)]) == 0
    images = sorted(folder.glob("*.png"))
    assert [p.name for p in images] == ["flight.ulg-battery1.png", "flight.ulg-battery2.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 20000 for p in images)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["absent.ulg"], "absent.ulg: cannot read file"),
        (["{flight}", "-o", "{tmp}"], "is a folder"),
        (["{flight}", "-o", "{tmp}/missing/r.html"], "no such folder"),
    ],
)
def test_errors_are_one_line(
    tmp_path: Path, flight: Path, capsys: pytest.CaptureFixture[str], args: list[str], expected: str
) -> None:
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    argv = [a.format(flight=flight, tmp=tmp_path, empty=empty) for a in args]
    code = main(["report", *argv])
    err = capsys.readouterr().err
    assert code == 2 and expected in err and "Traceback" not in err


def test_an_input_without_battery_records_is_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Readable, but nothing to report: exit 1 as for every command (--allow-empty: 0, nothing written)."""
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    assert main(["report", str(empty), "--message", "uorb.BatteryStatus", "-o", str(tmp_path / "r.html")]) == 1
    assert "expected battery records, found none (--allow-empty accepts that)" in capsys.readouterr().err
    assert main(["report", str(empty), "--message", "uorb.BatteryStatus", "--allow-empty"]) == 0
    assert not (tmp_path / "r.html").exists()


def test_json_format_gives_the_page_figures_per_battery(
    flight: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["report", "--format", "json", str(flight)]) == 0
    text = capsys.readouterr().out
    assert "NaN" not in text and "Infinity" not in text  # unknown is null: JSON has no NaN
    doc = json.loads(text)
    assert doc["format"] == "battgen-report" and doc["version"] == 1
    [item] = doc["inputs"]
    assert [b["battery"] for b in item["batteries"]] == [0, 1]
    for battery, series in zip(item["batteries"], read_input(flight, bundled_schemas()).batteries, strict=True):
        page = compute(series)
        assert battery["figures"]["charge_used_mah"] == page.charge_used_mah
        assert battery["figures"]["energy_used_wh"] == page.energy_used_wh
        # the flight's figures in SI: the same numbers, in coulombs and joules
        assert battery["flight"]["charge_used"] == pytest.approx(page.charge_used_mah * 3.6, rel=1e-12)
        assert battery["flight"]["records"] == 3000 and battery["flight"]["duration_s"] == page.duration_s
    out = tmp_path / "figures.json"
    assert main(["report", "--format", "json", "-o", str(out), str(flight)]) == 0
    assert json.loads(out.read_text()) == doc
    assert main(["report", "--format", "json", "-o", str(tmp_path), str(flight)]) == 2
    assert "is a folder" in capsys.readouterr().err


def test_json_format_carries_the_logs_modes_and_messages(capsys: pytest.CaptureFixture[str]) -> None:
    """The JSON report says what the page shows of the log: its mode changes and logged messages, as the data
    layer's context reads them (a real ArduPilot tlog: HEARTBEAT modes, STATUSTEXT)."""
    from shared_data import require, shared

    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.readers import read_log

    log = require(shared("corpus", "realworld3", "tlog", "uavlogviewer_vtol.tlog"))
    assert main(["report", "--format", "json", str(log)]) == 0
    [item] = json.loads(capsys.readouterr().out)["inputs"]
    context = next(b.context for b in read_log(log, log.name, bundled_catalog()) if b.context is not None)
    assert item["log"]["modes"] == [{"t": t, "mode": m} for t, m in context.modes] and len(context.modes) == 4
    assert [x["text"] for x in item["log"]["texts"]] == [x.text for x in context.texts] and context.texts
    assert item["log"]["firmware"] == "ArduPlane V3.10.0-dev (f2b4e06a)"


def test_png_images_show_the_logs_modes_and_armed_spans(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A PNG shows what the page shows of the log: the armed spans shaded and every mode change named (a real
    ArduPilot tlog), taken from the same facts as the HTML page."""
    pytest.importorskip("matplotlib")
    from matplotlib.axes import Axes
    from shared_data import require, shared

    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.readers import read_log

    log = require(shared("corpus", "realworld3", "tlog", "uavlogviewer_vtol.tlog"))
    context = next(b.context for b in read_log(log, log.name, bundled_catalog()) if b.context is not None)
    texts: list[str] = []
    spans: list[tuple[float, float]] = []
    real_text, real_span = Axes.text, Axes.axvspan

    def text(self: Axes, x: float, y: float, s: str, *args: object, **kwargs: object) -> object:
        texts.append(s)
        return real_text(self, x, y, s, *args, **kwargs)  # type: ignore[arg-type]

    def axvspan(self: Axes, xmin: float, xmax: float, *args: object, **kwargs: object) -> object:
        spans.append((xmin, xmax))
        return real_span(self, xmin, xmax, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Axes, "text", text)
    monkeypatch.setattr(Axes, "axvspan", axvspan)
    assert main(["report", str(log), "--format", "png", "-o", str(tmp_path / "images")]) == 0
    assert [name for _, name in context.modes] == [t for t in texts if t in {n for _, n in context.modes}]
    armed = context.armed_intervals(float("inf"))
    assert armed and {(a, b) for a, b in spans} >= {(a, b) for a, b in armed if b != float("inf")}


def test_json_report_carries_the_logs_events(capsys: pytest.CaptureFixture[str]) -> None:
    """``--format json`` gives an ArduPilot log's EV records by name, as the battery view's context holds them (a
    real DataFlash log of ArduCopter 3.3: SET_HOME, ARMED, AUTO_ARMED, NOT_LANDED)."""
    from shared_data import require, shared

    from codegen.apps.battery.catalog import bundled_catalog
    from codegen.apps.battery.readers import read_log

    log = require(shared("corpus", "realworld3", "dataflash", "dronekit_log171.bin"))
    assert main(["report", "--format", "json", str(log)]) == 0
    [item] = json.loads(capsys.readouterr().out)["inputs"]
    context = next(b.context for b in read_log(log, log.name, bundled_catalog()) if b.context is not None)
    assert item["log"]["events"] == [{"t": t, "event": e} for t, e in context.events]
    assert [e for _, e in context.events] == ["SYSTEM_TIME_SET", "SET_HOME", "ARMED", "AUTO_ARMED", "NOT_LANDED"]
