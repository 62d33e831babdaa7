"""The generated C library's codecs and validators, proven against the Python package: the library's
sources compile with ``gcc -std=c99 -Wall -Wextra -Wconversion -Werror -pedantic``, and a harness
(tests/c_cases.py) replays every record of every conformance vector and seeded random records per
message through the C and compares, case by case, with the generated Python package: the same bytes
(MAVLink 2 payloads with extension truncation, frames with CRC_EXTRA, signed frames read, MAVLink 1
frames; uORB structs at PX4's offsets; DroneCAN payloads with and without the tail array
optimisation), the same decoded values (floats by their bits: -0.0, float16 rounding; NaN as NaN),
the same validator problems. A corrupted frame is refused by its checksum."""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
from c_cases import Replay, collect, expected_lines, render_harness
from rust_cases import generated_classes

from codegen.apps.package import bundled_schemas, project_root
from codegen.frontends.loader import load

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
SOURCES = ("mavlink.c", "uorb.c", "dronecan.c")
needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")


@dataclass(frozen=True)
class Built:
    replays: list[Replay]
    output: list[str]


def compile_and_run(cc: list[str], run: list[str], tmp: Path, replays: list[Replay]) -> list[str]:
    """The library and the harness built by ``cc`` in ``tmp``, run (through ``run``, an emulator or
    nothing); the harness's lines."""
    schema = load([bundled_schemas()])
    harness = tmp / "main.c"
    harness.write_text(render_harness(schema, replays), encoding="utf-8")
    objects = []
    for src in SOURCES:
        obj = tmp / (src + ".o")
        done = subprocess.run(
            [*cc, *FLAGS, "-I", str(GENERATED), "-c", str(GENERATED / src), "-o", str(obj)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert done.returncode == 0, done.stderr[-4000:]
        objects.append(str(obj))
    exe = tmp / "replay"
    done = subprocess.run(
        [*cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-I", str(GENERATED), str(harness), *objects, "-lm", "-o", str(exe)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    ran = subprocess.run([*run, str(exe)], capture_output=True, text=True, timeout=300, check=False)
    assert ran.returncode == 0, ran.stderr[-4000:]
    return ran.stdout.splitlines()


def mismatches(replays: list[Replay], output: list[str]) -> list[str]:
    """Every expected line the harness did not print as expected (and lines it printed too many)."""
    got: dict[str, str] = {}
    for line in output:
        key, _, rest = line.partition(" ")
        tag, _, rest = rest.partition(" ")
        got[f"{key} {tag}"] = rest
    expected = expected_lines(replays)
    bad = [
        f"{key}:\n  C:      {got.get(key, '<missing>')[:300]}\n  Python: {line[:300]}"
        for key, line in expected
        if line is not None and got.get(key) != line
    ]
    extra = set(got) - {key for key, _ in expected}
    return bad + [f"unexpected line {key}" for key in sorted(extra)]


@pytest.fixture(scope="module")
def replays() -> list[Replay]:
    schema = load([bundled_schemas()])
    return collect(schema, generated_classes(schema))


@pytest.fixture(scope="module")
def native(replays: list[Replay], tmp_path_factory: pytest.TempPathFactory) -> Built:
    if shutil.which("gcc") is None:
        pytest.skip("gcc not installed")
    return Built(replays, compile_and_run(["gcc"], [], tmp_path_factory.mktemp("c"), replays))


def test_cases_reach_every_codec(replays: list[Replay]) -> None:
    counts = {r.msg.qualified_name: len(r.cases) for r in replays}
    for qualified in (
        "mavlink.BATTERY_STATUS",
        "mavlink.BATTERY_STATUS_V2",
        "uorb.BatteryStatus",
        "dronecan.uavcan.equipment.power.BatteryInfo",
        "dronecan.ardupilot.equipment.power.BatteryInfoAux",
    ):
        assert counts.get(qualified, 0) >= 40, counts
    assert {r.kind for r in replays} == {"mavlink", "uorb", "dronecan"}
    lines = [line for _, line in expected_lines(replays) if line]
    assert any(" range" in line for line in lines), "no case breaks a range"
    assert any(" nan" in line for line in lines), "no case holds a NaN where it is not allowed"


@needs_gcc
def test_c_replays_every_case_as_python(native: Built) -> None:
    bad = mismatches(native.replays, native.output)
    assert not bad, f"{len(bad)} differences, first:\n" + "\n".join(bad[:10])
    assert len(native.output) == len(expected_lines(native.replays))


@needs_gcc
def test_a_wrong_byte_is_seen(native: Built) -> None:
    """The comparison compares: one uORB case's expected struct with its first byte changed differs."""
    status = next(r for r in native.replays if r.msg.qualified_name == "uorb.BatteryStatus")
    case = status.cases[0]
    tag, line = case.expected[0]
    assert tag == "enc" and line
    changed = f"{(int(line[:2], 16) + 1) % 256:02x}" + line[2:]
    broken = Replay(status.kind, status.msg, [type(case)(case.cid, case.given, case.exact, case.wires, [(tag, changed)])])
    output = [o for o in native.output if o.startswith("uorb.BatteryStatus#0 enc ")]
    assert mismatches([broken], output) != []
    assert mismatches([Replay(status.kind, status.msg, [type(case)(case.cid, case.given, case.exact, case.wires, [(tag, line)])])], output) == []
