"""The Rust crate's converters (``battgen::convert``, generated/rust/src/convert.rs), proven against
the Python package as the C library's are (test_c_converters.py): every vector's input and the
same seeded random records per converter (with and without the optional companion message, the
inputs given or not) go through the Rust converter (one `cargo test` of a harness written at test
time, tests/rust_convert_cases.py) and through the Python package's converter under the same
policy; the targets must be the same value by value (floats by their bits, NaN as NaN, so -0.0 and
float16 rounding show) and the loss reports the same entries (kind and field) in the same order.
The Rust and C crates convert the same converters, routed alike."""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
from rust_convert_cases import RANDOM, Case, cases, render

from codegen.apps.conversion.vectors import SIDES
from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.backends.c.converters import c_converters
from codegen.backends.rust.converters import RustConverter, rust_converters
from codegen.frontends.loader import load

GENERATED = project_root() / "generated" / "rust"
needs_cargo = pytest.mark.skipif(shutil.which("cargo") is None, reason="cargo not installed")


@dataclass(frozen=True)
class Run:
    convs: list[tuple[RustConverter, list[Case]]]
    skipped: int
    output: dict[str, str]


def _cargo_test(root: Path, out: Path) -> None:
    env = {
        **os.environ,
        "CARGO_TARGET_DIR": str(root.parent / "target"),
        "CARGO_NET_OFFLINE": "true",
        "BATTGEN_CONVERT_OUT": str(out),
    }
    done = subprocess.run(
        ["cargo", "test", "--offline", "--test", "convert_replay"],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        check=False,
        timeout=1200,
    )
    assert done.returncode == 0, (done.stdout + done.stderr)[-4000:]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Run:
    if shutil.which("cargo") is None:
        pytest.skip("cargo not installed")
    schema = load([bundled_schemas()])
    made, _, _ = rust_converters(schema)
    convs = []
    skipped = 0
    for conv in made:
        found, lost = cases(schema, conv)
        convs.append((conv, found))
        skipped += lost
    work = tmp_path_factory.mktemp("rustconv")
    root = work / "battgen"
    shutil.copytree(GENERATED, root, ignore=shutil.ignore_patterns("target", "Cargo.lock"))
    (root / "tests").mkdir()
    (root / "tests" / "convert_replay.rs").write_text(render(schema, convs), encoding="utf-8")
    out = work / "out.txt"
    _cargo_test(root, out)
    lines = out.read_text(encoding="utf-8").splitlines()
    return Run(convs, skipped, dict(line.split(" ", 1) for line in lines))


def differences(run: Run, output: dict[str, str]) -> list[str]:
    bad = []
    for conv, found in run.convs:
        for j, case in enumerate(found):
            got = output.get(f"{conv.name}#{j}")
            if got != case.expected:
                bad.append(f"{conv.name} {case.cid}:\n  Rust:   {got}\n  Python: {case.expected}")
    return bad


def test_rust_has_the_c_librarys_converters_on_the_same_routes() -> None:
    schema = load([bundled_schemas()])
    made, _, left = rust_converters(schema)
    c_made, _, c_left = c_converters(schema)
    rust = {(c.source, c.target, c.policy): [(f.edge.mapping.name, f.edge.function) for f in c.chain] for c in made}
    c = {(k.source, k.target, k.policy): [(f.edge.mapping.name, f.edge.function) for f in k.chain] for k in c_made}
    assert len(rust) >= 90
    assert rust == c
    assert [w.replace("Rust", "C") for w in left] == c_left


@needs_cargo
def test_dronecan_to_uorb_is_in_rust_under_both_policies(run: Run) -> None:
    names = {conv.name for conv, _ in run.convs}
    assert {"dronecan_to_uorb_strict", "dronecan_to_uorb_px4"} <= names
    for conv, found in run.convs:
        vectors = [c for c in found if c.cid.startswith("vector/")]
        assert len(found) - len(vectors) >= RANDOM // 2, (conv.name, len(found), run.skipped)
        assert len(vectors) >= 40 or conv.source not in SIDES, conv.name


@needs_cargo
def test_rust_converts_every_case_as_python(run: Run) -> None:
    bad = differences(run, run.output)
    compared = sum(len(found) for _, found in run.convs)
    assert compared > 10_000
    assert not bad, f"{len(bad)} of {compared} differ, first:\n" + "\n".join(bad[:5])
    lines = " ".join(c.expected for _, found in run.convs for c in found)
    for kind in ("unknown", "dropped", "clamped", "rounded"):  # the cases reach every kind the converters report
        assert f"{kind} " in lines, kind
    assert "=nan;" in lines and "=80000000;" in lines  # NaN and -0.0 among the values compared


@needs_cargo
def test_a_changed_value_is_seen(run: Run) -> None:
    """The comparison compares: a case's expected line with one float's bits changed differs from Rust's."""
    conv, found = next((c, k) for c, k in run.convs if c.name == "dronecan_to_uorb_px4")
    line = found[0].expected
    changed = line.replace("voltage_v=", "voltage_v=1", 1)
    assert changed != line and run.output[f"{conv.name}#0"] == line != changed
