"""The crate's BATT_* parameter table (`battgen::params::BATT`, generated from the parameter metadata IR) is
the Python package's (generated/params.py: names, types, defaults, ranges, units, named values), and its
per-vehicle failsafe tables (`battgen::failsafe::Vehicle`: each action code's meaning on Rover, Copter, Plane
and Sub, the priority list, the handlers' fallbacks in every situation, the default BATT_LOW_VOLT) and the
battery prefixes and a battery's settings read from a parameter set (`Settings::from_params`) are battgen's
(codegen/apps/failsafe/vehicles.py, settings.py). The crate prints them
(backends/rust_params_table.rs); every line must be the one Python gives."""

from __future__ import annotations

import dataclasses
import enum
import shutil
import struct

import pytest
from rust_crate import Crate, cargo, shared_crate

import generated.params as params
from codegen.apps.failsafe.settings import MAX_INSTANCES, BatterySettings, prefix
from codegen.apps.failsafe.vehicles import VEHICLES, Situation

needs_cargo = pytest.mark.skipif(shutil.which("cargo") is None, reason="cargo not installed")


@pytest.fixture(scope="module")
def crate(tmp_path_factory: pytest.TempPathFactory) -> Crate:
    return shared_crate(tmp_path_factory)


# the parameter sets (battery 1's names without BATT_) rust_params_table.rs gives Settings::from_params
SETTINGS: list[dict[str, float]] = [
    {},
    {"LOW_VOLT": 11.1, "CRT_MAH": 400.0, "FS_LOW_ACT": 2.0, "MONITOR": 4.0},
    {"CAPACITY": 5000.0, "LOW_TIMER": 0.3, "FS_CRT_ACT": 5.0, "FS_VOLTSRC": 1.0},
]


def _bits(value: float | None) -> str:
    return "-" if value is None else struct.pack(">d", float(value)).hex()


def _enum_codes(qualified: str) -> list[int]:
    """The codes of a generated enum of params (its docstring starts with its qualified name)."""
    for obj in vars(params).values():
        if isinstance(obj, type) and issubclass(obj, enum.IntEnum) and (obj.__doc__ or "").startswith(qualified + ":"):
            return [int(m) for m in obj]
    raise AssertionError(f"no generated enum {qualified}")


def expected_lines() -> list[str]:
    out: list[str] = []
    for f in dataclasses.fields(params.BattParams):
        m = f.metadata
        codes = [c for q in m["enums"] for c in _enum_codes(q)]
        out.append(
            f"param {m['name']} {m['type']} {_bits(f.default)} {_bits(m['minimum'])} {_bits(m['maximum'])} "
            f"{m['unit'] or '-'} {','.join(map(str, codes))}"
        )
    for name in ("rover", "copter", "plane", "sub"):
        v = VEHICLES[name]
        d = BatterySettings.from_values({}, 1, v)
        out.append(f"defaults {name} {_bits(d.capacity_mah)} {_bits(d.low_volt)} {_bits(d.low_timer_s)}")
        for k, values in enumerate(SETTINGS):
            s = BatterySettings.from_values({"BATT_" + n: x for n, x in values.items()}, 1, v)
            numbers = (s.capacity_mah, s.low_volt, s.low_timer_s, s.low_mah, s.crt_volt, s.crt_mah)
            monitor = "-" if s.monitor is None else s.monitor
            out.append(f"settings {name} {k} {' '.join(map(_bits, numbers))} {s.low_action} {s.crt_action} "
                       f"{s.volt_source} {monitor}")  # fmt: skip
        for critical in (0, 1):
            table = v.actions("critical" if critical else "low")
            out.extend(
                f"action {name} {critical} {code} {v.priority(code)}|{table.get(code, '-')}" for code in range(-1, 8)
            )
        for code in range(-1, 8):
            for mask in range(32):
                flags = [bool(mask >> bit & 1) for bit in range(5)]
                out.append(f"resolve {name} {code} {mask} {v.resolve(code, Situation(*flags))}")
    for i in range(MAX_INSTANCES + 2):
        out.append(f"prefix {i} {prefix(i) if 1 <= i <= MAX_INSTANCES else '-'}")
    return out


def test_the_tables_are_worth_comparing() -> None:
    lines = expected_lines()
    assert sum(line.startswith("param ") for line in lines) == 11
    assert "param BATT_LOW_TIMER int8 " + _bits(10) + " " + _bits(0) + " " + _bits(120) + " s " in lines
    # the seed's mistake is in the table the crate must match: Rover's 1 is RTL, 2 Hold
    assert "action rover 0 1 2|RTL" in lines and "action rover 0 2 1|Hold" in lines
    outcomes = {line.rsplit(" ", 1)[1] for line in lines if line.startswith("resolve ")}
    assert len(outcomes) >= 10, outcomes


@needs_cargo
def test_the_crate_prints_pythons_tables(crate: Crate) -> None:
    done = cargo(crate, "test", "--offline", "--test", "params_table", "--", "--nocapture")
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    kinds = {"param", "defaults", "settings", "action", "resolve", "prefix"}
    got = [line for line in done.stdout.splitlines() if line.split(" ", 1)[0] in kinds]
    assert got == expected_lines()
