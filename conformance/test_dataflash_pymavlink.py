"""Our DataFlash battery readings against pymavlink's DFReader on every real DataFlash log of the
shared corpus: per instance the count, first/last time and min/max voltage, max current, last
CurrTot, in V / A / mAh (pre-3.6 CURR is int16 hundredths, scaled as ArduPilot's logging code wrote it).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from shared_data import SHARED

from codegen.inputs.dataflash.log import NUMBERED_TYPES, battery_records, open_log
from codegen.inputs.dataflash.text import HEAD_BYTES, is_text_dataflash
from codegen.inputs.dataflash.units import field_scales

CORPUS = SHARED / "corpus"


def _logs() -> list[Path]:
    if not CORPUS.is_dir():
        return []
    binary = [p for p in CORPUS.rglob("*") if p.suffix.lower() == ".bin" and p.is_file()]
    text = [p for p in CORPUS.rglob("*.log") if p.is_file() and is_text_dataflash(p.read_bytes()[:HEAD_BYTES])]
    return sorted(binary + text)


LOGS = _logs()


def test_corpus_present() -> None:
    if not LOGS:
        if os.environ.get("CI"):
            pytest.fail(f"no DataFlash logs under {CORPUS}")
        pytest.skip(f"no DataFlash logs under {CORPUS}")


def _reference(path: Path) -> dict[int, list[tuple[float, float, float, float]]]:
    from pymavlink import DFReader

    text = path.suffix.lower() != ".bin"
    reader = (DFReader.DFReader_text if text else DFReader.DFReader_binary)(str(path), zero_time_base=True)
    out: dict[int, list[tuple[float, float, float, float]]] = {}
    types = ["BAT", "BATT", "CURR", *NUMBERED_TYPES]
    while (msg := reader.recv_match(type=types)) is not None:
        d = msg.to_dict()
        fmt = msg.fmt
        scale = field_scales(msg.get_type(), fmt.format, fmt.columns, bool(getattr(fmt, "units", None)))
        inst = NUMBERED_TYPES.get(msg.get_type(), int(d.get("Inst", d.get("Instance", 0))))
        t = d["TimeUS"] / 1e6 if "TimeUS" in d else d["TimeMS"] / 1e3 if "TimeMS" in d else msg._timestamp
        row = (t, d["Volt"] * scale["Volt"], d["Curr"] * scale["Curr"], float(d["CurrTot"]))
        out.setdefault(inst, []).append(row)
    return out


@pytest.mark.parametrize("path", LOGS, ids=[p.name for p in LOGS])
def test_battery_readings_match_pymavlink(path: Path) -> None:
    ours: dict[int, list[tuple[float, float, float, float]]] = {}
    for r in battery_records(open_log(path)):
        assert r.voltage_v is not None and r.current_a is not None and r.consumed_mah is not None
        ours.setdefault(r.instance, []).append((r.time_s, r.voltage_v, r.current_a, r.consumed_mah))
    ref = _reference(path)
    assert ours.keys() == ref.keys() and ours
    for inst, rows in ref.items():
        mine = ours[inst]
        assert len(mine) == len(rows)
        assert mine[0][0] == pytest.approx(rows[0][0]) and mine[-1][0] == pytest.approx(rows[-1][0])
        for col in (1, 2):
            assert max(m[col] for m in mine) == pytest.approx(max(r[col] for r in rows), rel=1e-6)
        assert min(m[1] for m in mine) == pytest.approx(min(r[1] for r in rows), rel=1e-6)
        assert mine[-1][3] == pytest.approx(rows[-1][3], rel=1e-6)


def test_pre_36_curr_reads_volts_and_amps() -> None:
    logs = [p for p in LOGS if p.name == "dronekit_log171.bin"]
    if not logs:
        pytest.skip("dronekit_log171.bin (ArduCopter 3.3) not in the corpus")
    rows = list(battery_records(open_log(logs[0])))
    volts = [r.voltage_v for r in rows if r.voltage_v is not None]
    amps = [r.current_a for r in rows if r.current_a is not None]
    # a 4S pack: ~16.8 V full, never the 1491 V the raw int16 hundredths would read
    assert 10 < min(volts) < max(volts) < 17.5
    assert 0 <= max(amps) < 100


def test_text_log_read() -> None:
    text = [p for p in LOGS if p.suffix.lower() == ".log"]
    if not text:
        pytest.skip("no text DataFlash log in the corpus")
    for path in text:
        rows = list(battery_records(open_log(path)))
        assert rows and all(r.voltage_v is not None and 5 < r.voltage_v < 60 for r in rows)


def test_legacy_scale_table() -> None:
    for fmt in ("hIhhhf", "IhIhhhf", "IhhhHf", "IhhhHfh", "QhhhHfh"):
        cols = {
            "hIhhhf": ["Thr", "ThrInt", "Volt", "Curr", "Vcc", "CurrTot"],
            "IhIhhhf": ["TimeMS", "Thr", "ThrInt", "Volt", "Curr", "Vcc", "CurrTot"],
            "IhhhHf": ["TimeMS", "Thr", "Volt", "Curr", "Vcc", "CurrTot"],
            "IhhhHfh": ["TimeMS", "Thr", "Volt", "Curr", "Vcc", "CurrTot", "Volt2"],
            "QhhhHfh": ["TimeUS", "Thr", "Volt", "Curr", "Vcc", "CurrTot", "Volt2"],
        }[fmt]
        s = field_scales("CURR", fmt, cols, False)
        assert s["Volt"] == s["Curr"] == 0.01 and s["CurrTot"] == 1.0
    assert field_scales("CURR", "Qfff", ["TimeUS", "Volt", "Curr", "CurrTot"], False)["Volt"] == 1.0
    assert field_scales("BAT", "QBfff", ["TimeUS", "Inst", "Volt", "Curr", "CurrTot"], True)["Volt"] == 1.0
