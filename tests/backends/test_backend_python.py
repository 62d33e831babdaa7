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
from conftest import ROOT
from samples import EVIL, hostile_schema

from codegen.backends.python import render_package


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


# Statements ruff breaks or normalises, each one line as an emitter writes it.
FORMAT_CASES = (
    "_SPEC = _v.Number(type='float32', kind='float', low=-3.4028234663852886e+38, "
    "high=3.4028234663852886e+38, unit='V', mask=0x7ff)",
    "_TABLE: tuple[tuple[str, str, str, int], ...] = (('timestamp', 'timestamp', 'Q', 0), ('voltage_v', "
    "'voltage_v', 'f', 0), ('current_a', 'current_a', 'f', 0))",
    "x = (first_operand_with_a_long_name & 0xff) | (((second_operand_with_a_long_name >> 8) & 0x7) << "
    "13) | (third_operand << 22)",
    "y = value_with_a_long_name if -65504.0 <= value_with_a_long_name <= 65504.0 else (65504.0 if "
    "value_with_a_long_name > 0 else -65504.0)",
    "out.append(_v.rule('voltage_cell_v' + '[' + str(v_i) + ']', 'cells-beyond-count-zero', "
    "r_voltage_cell_v[v_i], 'voltage_cell_v[i] == 0'))",
    "if (x := self.over_voltage_threshold_microvolt) is not None and (len(x) < 1 or any((len(_x0) < 1 or "
    "any(((_x1 + 2147483648) & -4294967296) for _x1 in _x0)) for _x0 in x)):\n    pass",
    "while some_condition_with_a_long_name and another_condition_with_a_long_name or "
    "yet_another_condition_with_a_long_name_here:\n    pass",
    "for key, value in sorted(some_mapping_with_a_long_name.items(), key=lambda item: (item[1], "
    "item[0]), reverse=True)[:limit_with_a_long_name]:\n    pass",
    "default: list[float] = dataclasses.field(default_factory=lambda: [0.0] * 14, "
    "metadata=_m.meta(name='voltage_cell_v', type='float32[14]', doc='Battery individual cell voltages, "
    "' 'one per cell, ' 'zero where unknown'))",
    "g1, g2, g3 = _FLOAT32_BITS.unpack(_FLOAT32.pack((r1 if -65504.0 <= r1 <= 65504.0 else 65504.0), (r2 "
    "if -65504.0 <= r2 <= 65504.0 else 65504.0)))",
    "raise _uorb.DecodeError('BatteryStatus: expected 168 bytes (or 166 without the trailing padding), "
    "got ' + str(len(data)))",
    "return {'current_consumed': c[0], 'energy_consumed': c[1], 'temperature': c[2], 'voltages': "
    "list(zip(*c[3:13], strict=True))}",
    "value = {key_with_a_long_name: [item.to_dict() for item in values_with_a_long_name] for "
    "key_with_a_long_name, values_with_a_long_name in data.items()}",
    "short = ('a', 'b',)",
    "def forward(s_info: _C0, s_aux: _C1 | None = None, *, rep: _r.LossReport | None = None, "
    "rep_d: _r.LossReport | None = None) -> tuple[BatteryState]:\n    pass",
    "def from_ulog(cls, source: _ulog.Source | _ulog.Log, *, topic: str | None = None, multi_id: int = 0) "
    "-> list[BatteryStatus]:\n    pass",
    "from . import devicetree, dronecan, dronecan_devicetree, dronecan_mavlink, dronecan_uorb, "
    "dronecan_uorb_v0, mavlink, mavlink_devicetree, uorb",
    "parenthesized = (a + b)",
    "text = 'it\\'s \"quoted\"'",
    "nested = outer_function(inner_function(argument_one, argument_two, argument_three), "
    "other_inner(argument_four, argument_five))",
)


def _cases_module() -> str:
    body = "\n\n".join(FORMAT_CASES).replace("\n", "\n    ").replace("\n    \n", "\n\n")
    return f"def f():\n    {body}\n"


def test_generation_formats_as_the_projects_ruff_settings_check(tmp_path: Path) -> None:
    """The settings generation passes ruff are the ones generated/ is checked against (pyproject.toml)."""
    from codegen.backends.python.formatting import ruff_format

    source = _cases_module()
    formatted = ruff_format({"cases.py": source})["cases.py"]
    assert formatted != source  # the long statements were broken
    path = tmp_path / "cases.py"
    path.write_text(formatted)
    proc = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--diff", "--config", str(ROOT / "pyproject.toml"), str(path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_generation_formatting_ignores_ruff_configuration_on_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ruff.toml above the folder ruff runs in (another line length, single quotes) changes nothing."""
    import tempfile

    from codegen.backends.python.formatting import ruff_format

    files = {"cases.py": _cases_module(), "README.txt": "not Python"}
    plain = ruff_format(files)
    (tmp_path / "ruff.toml").write_text('line-length = 40\n[format]\nquote-style = "single"\n')
    (tmp_path / "pyproject.toml").write_text("[tool.ruff]\nline-length = 40\n")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    assert ruff_format(files) == plain
    assert plain["README.txt"] == "not Python"
    assert 'short = ("a", "b",)' not in plain["cases.py"] and '"a",\n' in plain["cases.py"]  # magic trailing comma


def test_generated_models_of_hostile_schemas_are_formatted(tmp_path: Path) -> None:
    from codegen.backends.python.writer import generate

    generate(hostile_schema(), tmp_path / "genpkg")
    # the models, not the runtime modules copied into the package (files named _*.py)
    models = [str(p) for p in (tmp_path / "genpkg").rglob("*.py") if not p.stem.startswith("_") or p.stem == "__init__"]
    proc = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--check", "--config", str(ROOT / "pyproject.toml"), *models],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
