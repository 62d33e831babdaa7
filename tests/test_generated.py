"""The committed generated/ package: fresh, deterministic, importable, typed."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
import time

from conftest import ROOT

from codegen.backends.python import render_package
from codegen.backends.python.writer import generate
from codegen.frontends.loader import load


def test_generated_is_fresh() -> None:
    result = generate(load([ROOT / "schemas"]), ROOT / "generated", check=True)
    assert result.stale == (), f"generated/ is stale, run 'battgen generate': {result.stale}"


def test_generation_is_deterministic_and_fast() -> None:
    started = time.perf_counter()
    first = render_package(load([ROOT / "schemas"]))
    elapsed = time.perf_counter() - started
    assert first == render_package(load([ROOT / "schemas"]))
    assert elapsed < 5.0  # the figure itself is reported by benchmarks/, this only catches blow-ups


def test_models_default_to_sentinels() -> None:
    from generated.mavlink import BatteryStatus as Mav
    from generated.uorb import BatteryStatus

    status = BatteryStatus()
    assert status.voltage_v == 0 and status.current_a == -1 and math.isnan(status.temperature)
    assert status.remaining == -1 and status.voltage_cell_v == [0.0] * 14
    mav = Mav()
    assert mav.temperature == 32767 and mav.voltages == [65535] * 10 and mav.current_battery == -1
    meta = {f.name: f.metadata for f in dataclasses.fields(BatteryStatus)}
    assert meta["voltage_v"]["unit"] == "V" and meta["remaining"]["minimum"] == 0
    assert meta["warning"]["enums"] == ("uorb.BatteryStatus.WARNING",)


def test_generated_package_is_mypy_clean() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-incremental", "-p", "generated"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_generated_imports_only_the_standard_library() -> None:
    stdlib = set(sys.stdlib_module_names)
    for path in (ROOT / "generated").rglob("*.py"):
        for line in path.read_text(encoding="utf-8").splitlines():
            words = line.split()
            if words[:1] == ["import"] or (words[:1] == ["from"] and not words[1].startswith(".")):
                assert words[1].split(".")[0] in stdlib | {"__future__"}, f"{path}: {line}"
