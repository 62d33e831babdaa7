"""The Python backend on hand-built IR: hostile names and docs stay inert, output is deterministic,
generated code is importable, typed and round-trips plain data."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from codegen.backends.python import render_package
from codegen.ir import (
    ArrayType,
    CompositeType,
    Constant,
    DevicetreeInfo,
    DronecanInfo,
    DronecanKind,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Location,
    Message,
    PrimitiveKind,
    PrimitiveType,
    Range,
    Schema,
    Sentinel,
    SourceFormat,
    StringType,
    units,
)

L = Location("hostile.msg", 3)
U8 = PrimitiveType(PrimitiveKind.UINT, 8)
F32 = PrimitiveType(PrimitiveKind.FLOAT, 32)
EVIL = '""" + __import__("os").system("echo pwned") + """ \\ \' \x00 \r # {{ x }} {% if %}'


def _dronecan(name: str) -> DronecanInfo:
    return DronecanInfo(name, None, 1, DronecanKind.MESSAGE, False, 8, 8, 8, 8, "")


def hostile_schema() -> Schema:
    inner = Message(
        "In", "dronecan.ns.In", SourceFormat.DRONECAN, L, EVIL, (Field("v", U8, L),), dronecan=_dronecan("ns.In")
    )
    weird = Message(
        "class",
        "uorb.class",
        SourceFormat.UORB,
        L,
        EVIL,
        (
            Field("class", U8, L, doc=EVIL, unit=units.opaque(EVIL), unit_text=EVIL),
            Field("to_dict", F32, L, invalid=Sentinel(math.nan, "NaN"), range=Range(0, None)),
            Field("1st", ArrayType(F32, 3, False), L, invalid=Sentinel(0, "0", per_element=True)),
            Field("a b", StringType(8), L, default=EVIL),
            Field("QUALIFIED_NAME", PrimitiveType(PrimitiveKind.INT, 16), L, invalid=Sentinel(32767, "INT16_MAX")),
            Field("", PrimitiveType(PrimitiveKind.VOID, 3), L),
        ),
        constants=(
            Constant("class", U8, 1),
            Constant("S", StringType(), EVIL),
            Constant("E_A", U8, 0),
            Constant("E_B", U8, 1),
        ),
        enums=(EnumDef("uorb.class.E", EnumKind.VALUE, (EnumEntry("E_A", 0, EVIL), EnumEntry("E_B", 1)), EVIL),),
    )
    outer = Message(
        "Out",
        "dronecan.other.Out",
        SourceFormat.DRONECAN,
        L,
        "",
        (
            Field("inner", CompositeType("dronecan.ns.In"), L),
            Field("many", ArrayType(CompositeType("dronecan.ns.In"), 2, False), L),
        ),
        dronecan=_dronecan("other.Out"),
    )
    dt = Message(
        "battery",
        "devicetree.power.supply.battery",
        SourceFormat.DEVICETREE,
        L,
        "",
        (
            Field("compatible", StringType(), L, const="simple-battery", required=True),
            Field("voltage-min-design-microvolt", PrimitiveType(PrimitiveKind.UINT, 32), L, unit=units.unit("uV")),
            Field(
                "^t-[0-9]+$",
                ArrayType(ArrayType(PrimitiveType(PrimitiveKind.UINT, 32), 2, False), None, True),
                L,
                pattern="^t-[0-9]+$",
            ),
        ),
        devicetree=DevicetreeInfo("x", "t", ("simple-battery",), ("compatible",), False),
    )
    return Schema((outer, inner, weird, dt))


def test_output_is_deterministic() -> None:
    assert render_package(hostile_schema()) == render_package(hostile_schema())


def test_hostile_text_stays_inert_and_valid(import_generated: Any, capfd: pytest.CaptureFixture[str]) -> None:
    files = render_package(hostile_schema())
    for rel, text in files.items():
        compile(text, rel, "exec")  # every file is valid Python
    mod = import_generated(hostile_schema(), "uorb")
    assert "pwned" not in capfd.readouterr().out
    cls = mod.Class
    assert cls.__doc__.startswith(EVIL.replace("\x00", "\\x00").replace("\r", "\\x0d").split("\n")[0][:10])
    obj = cls()
    assert obj.class_ == 0 and math.isnan(obj.to_dict_) and obj.QUALIFIED_NAME_ == 32767
    assert cls.QUALIFIED_NAME == "uorb.class" and cls.S == EVIL and cls.class__ == 1
    assert obj.a_b == EVIL and obj._1st == [0.0, 0.0, 0.0]
    meta = {f.name: f.metadata for f in dataclasses.fields(cls)}
    assert meta["class_"]["doc"] == EVIL and meta["class_"]["unit"] == EVIL
    assert mod.ClassE.A == 0 and mod.ClassE.__doc__.startswith('""" +')


def test_round_trip_and_composites(import_generated: Any) -> None:
    pkg = import_generated(hostile_schema())
    from importlib import import_module

    other = import_module(pkg.__name__ + ".dronecan.other")
    out = other.Out.from_dict({"inner": {"v": 7}, "many": [{"v": 1}, {"v": 2}]})
    assert out.inner.v == 7 and [m.v for m in out.many] == [1, 2]
    assert other.Out.from_dict(out.to_dict()) == out
    with pytest.raises(ValueError, match=r"inner\.v: expected an integer"):
        other.Out.from_dict({"inner": {"v": "x"}})
    with pytest.raises(ValueError, match="many: expected exactly 2 items"):
        other.Out.from_dict({"many": [{"v": 1}]})


def test_devicetree_model_and_pattern_properties(import_generated: Any) -> None:
    dt = import_generated(hostile_schema(), "devicetree")
    node = dt.SimpleBattery.from_dict({"compatible": "simple-battery", "t-0": [[1, 2]], "t-12": [[3, 4]]})
    assert node.voltage_min_design_microvolt is None
    assert node.t_n == {"t-0": [[1, 2]], "t-12": [[3, 4]]}
    assert node.to_dict() == {"compatible": "simple-battery", "t-0": [[1, 2]], "t-12": [[3, 4]]}
    with pytest.raises(ValueError, match="x-1"):
        dt.SimpleBattery.from_dict({"x-1": 1})


def test_generated_code_is_mypy_clean(tmp_path: Path) -> None:
    from codegen.backends.python.writer import generate

    generate(hostile_schema(), tmp_path / "genpkg")
    proc = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-incremental", "genpkg"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
