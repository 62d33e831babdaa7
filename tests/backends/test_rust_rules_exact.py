"""Cross-field rules comparing an integer with a float, in the Rust crate as in Python: Python compares an
int with a float exactly (2^53 + 1 is above the float 2^53, NaN is unordered), where an f64 conversion of
the integer would round it. A small schema (a uORB message with 64-bit integers beside float64 and float32
bounds, and rules comparing them every way) is rendered as a crate and as a Python package; the same
values, integers beyond 2^53 among them, give the same problems through both validators."""

from __future__ import annotations

import importlib
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from codegen.backends.python.writer import generate
from codegen.backends.rust.render import render_crate
from codegen.frontends.loader import load

MESSAGE = """# A count beside float bounds
uint64 timestamp # time since system start (microseconds)
uint64 count # how many
int64 offset # signed
float64 limit # a float bound
float32 small # a float32 bound
"""

RULES = """doc: Integers beyond 2^53 compared with floats.
messages: [uorb.BigCount]
rules:
""" + "".join(
    f'  - id: {rid}\n    assert: "{check}"\n    path: {path}\n    message: "{rid} broken"\n'
    for rid, check, path in (
        ("count-within-limit", "count <= limit", "count"),
        ("count-is-not-limit", "count != limit", "count"),
        ("limit-above-count", "limit > count", "limit"),
        ("offset-below-small", "offset < small", "offset"),
        ("count-equals-limit", "count == limit", "count"),
        ("limit-at-least-count", "limit >= count", "limit"),
    )
)

TWO53 = 1 << 53
# (count, offset, limit, small): each is a different answer exact and through f64 for some rule
VALUES: list[tuple[int, int, float, float]] = [
    (TWO53 + 1, 0, float(TWO53), 0.0),
    (TWO53, 0, float(TWO53), 0.0),
    (TWO53 + 1, 0, float(TWO53 + 2), 0.0),
    ((1 << 64) - 1, 0, float(1 << 64), 0.0),
    (0, TWO53 + 1, math.nan, math.inf),
    (3, -(1 << 63), -0.0, -9.223372036854775808e18),
    (5, (1 << 63) - 1, 5.0, 9.223372036854775808e18),
    (TWO53 - 1, -(TWO53 + 1), float(TWO53 - 1), -float(TWO53)),
]


def _f64_bits(x: float) -> str:
    return f"f64::from_bits({int.from_bytes(__import__('struct').pack('<d', x), 'little'):#018x})"


def _f32_bits(x: float) -> str:
    return f"f32::from_bits({int.from_bytes(__import__('struct').pack('<f', x), 'little'):#010x})"


MAIN = """use battgen::uorb::BigCount;
use battgen::Validate;

fn main() {
CASES}
"""


@pytest.fixture(scope="module")
def schema_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("big_rules")
    (base / "uorb").mkdir()
    (base / "uorb" / "BigCount.msg").write_text(MESSAGE, encoding="utf-8")
    (base / "rules").mkdir()
    (base / "rules" / "big.yaml").write_text(RULES, encoding="utf-8")
    return base


def _python(schema_dir: Path, out: Path) -> list[str]:
    generate(load([schema_dir]), out / "big_rules_py")
    sys.path.insert(0, str(out))
    try:
        cls: Any = importlib.import_module("big_rules_py.uorb").BigCount
        lines = []
        for count, offset, limit, small in VALUES:
            obj = cls(count=count, offset=offset, limit=limit, small=small)
            lines.append(";".join(f"{v.path} {v.rule}" for v in obj.validate() if v.rule.startswith("cross")))
        return lines
    finally:
        sys.path.remove(str(out))
        for name in [n for n in sys.modules if n.split(".")[0] == "big_rules_py"]:
            del sys.modules[name]


def _rust(schema_dir: Path, base: Path) -> list[str]:
    crate = base / "crate"
    for rel, text in render_crate(load([schema_dir])).items():
        (crate / rel).parent.mkdir(parents=True, exist_ok=True)
        (crate / rel).write_text(text, encoding="utf-8")
    calls = []
    for count, offset, limit, small in VALUES:
        value = (
            f"BigCount {{ count: {count}, offset: {offset}, limit: {_f64_bits(limit)}, "
            f"small: {_f32_bits(small)}, ..BigCount::new() }}"
        )
        show = 'p.rule.name().to_string() + ":" + p.rule.rule_id().unwrap_or("")'
        calls.append(
            f"    let found: Vec<String> = {value}.validate().as_slice().iter()"
            f'.filter(|p| p.rule.rule_id().is_some()).map(|p| format!("{{}} {{}}", p.field, {show})).collect();\n'
            '    println!("{}", found.join(";"));\n'
        )
    (crate / "examples").mkdir()
    (crate / "examples" / "big.rs").write_text(MAIN.replace("CASES", "".join(calls)), encoding="utf-8")
    env = {**os.environ, "CARGO_TARGET_DIR": str(base / "target"), "CARGO_NET_OFFLINE": "true"}
    done = subprocess.run(
        ["cargo", "run", "--offline", "-q", "--example", "big"],
        cwd=crate,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout.splitlines()


@pytest.mark.skipif(shutil.which("cargo") is None, reason="cargo not installed")
def test_integers_beyond_2_53_compare_with_floats_as_python(
    schema_dir: Path, tmp_path_factory: pytest.TempPathFactory
) -> None:
    python = _python(schema_dir, tmp_path_factory.mktemp("big_py"))
    # the values tell exact from rounded: 2^53 + 1 is above the float 2^53, and not equal to it
    assert python[0] == (
        "count cross-field:count-within-limit;limit cross-field:limit-above-count;"
        "offset cross-field:offset-below-small;count cross-field:count-equals-limit;"
        "limit cross-field:limit-at-least-count"
    ), python[0]
    assert _rust(schema_dir, tmp_path_factory.mktemp("big_rs")) == python
