"""The generated C library's codecs and validators, proven against the Python package: the library's
sources compile with ``gcc -std=c99 -Wall -Wextra -Wconversion -Werror -pedantic``, and a harness
(tests/c_cases.py) replays every record of every conformance vector and seeded random records per
message through the C and compares, case by case, with the generated Python package: the same bytes
(MAVLink 2 payloads with extension truncation, frames with CRC_EXTRA, signed frames read, MAVLink 1
frames; uORB structs at PX4's offsets; DroneCAN payloads with and without the tail array
optimisation), the same decoded values (floats by their bits: -0.0, float16 rounding; NaN as NaN),
the same validator problems. A corrupted frame is refused by its checksum. Seeded random bytes and
damaged encodings go to every decoder (each input in a buffer of exactly its length) and must be
refused or read as the Python decoder refuses or reads them. The same replay runs under ASan and
UBSan, and built static for big-endian s390x under qemu; every source builds for a Cortex-M4 with no
C library; the MAVLink frames equal pymavlink's; the README's example runs."""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import pytest
from c_cases import Replay, add_fuzz, collect, expected_lines, render_harness
from rust_cases import generated_classes

from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.frontends.loader import load

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
SOURCES = ("mavlink.c", "uorb.c", "dronecan.c", "convert.c")
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
        [
            *cc,
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-I",
            str(GENERATED),
            str(harness),
            *objects,
            "-lm",
            "-o",
            str(exe),
        ],
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
    classes = generated_classes(schema)
    found = collect(schema, classes)
    add_fuzz(schema, found, classes)
    return found


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
    for rule in (
        "cells-beyond-count-zero",
        "cell-count-capacity",
        "state-of-health-percent",
        "battery-remaining-percent",
    ):
        assert any(f" cross-field:{rule}" in line for line in lines), f"no case breaks the cross-field rule {rule}"
    for r in replays:  # the fuzz inputs reach both the decoder's errors and its values
        results = [line for _, fuzz in r.fuzz for _, line in fuzz]
        assert "err" in results and any(line.startswith("0 ") for line in results), r.msg.qualified_name


@needs_gcc
def test_c_replays_every_case_as_python(native: Built) -> None:
    bad = mismatches(native.replays, native.output)
    assert not bad, f"{len(bad)} differences, first:\n" + "\n".join(bad[:10])
    assert len(native.output) == len(expected_lines(native.replays))


def _pymavlink_dialects(tmp: Path) -> dict[str, Any]:
    """pymavlink's generator (mavgen, Python) run on the bundled MAVLink XML: message name -> class."""
    from pymavlink.generator import mavgen

    classes: dict[str, Any] = {}
    for xml in sorted((bundled_schemas() / "mavlink").glob("*.xml")):
        out = tmp / f"pm_{xml.stem}.py"
        opts = mavgen.Opts(str(out), wire_protocol="2.0", language="Python3", validate=False)
        assert mavgen.mavgen(opts, [str(xml)])
        spec = importlib.util.spec_from_file_location(out.stem, out)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        classes.update({cls.msgname: cls for cls in module.mavlink_map.values()})
        classes["__mavlink__"] = module.MAVLink
    return classes


@needs_gcc
def test_c_frames_equal_pymavlink(native: Built, tmp_path: Path) -> None:
    """Every MAVLink 2 frame the C writes equals the frame pymavlink packs from the same values
    (pymavlink's own generator run on the same XML: BATTERY_INFO and BATTERY_STATUS_V2 are not in
    the dialects it ships)."""
    dialect = _pymavlink_dialects(tmp_path)
    frames = {}
    for line in native.output:
        key, _, rest = line.partition(" ")
        tag, _, rest = rest.partition(" ")
        if tag == "frame":
            frames[key] = rest
    compared = 0
    for r in native.replays:
        if r.kind != "mavlink":
            continue
        pm = dialect[r.msg.name]
        for j, case in enumerate(r.cases):
            args = []
            for name, ftype in zip(pm.fieldnames, pm.fieldtypes, strict=True):
                value = case.record[name]
                args.append(value.encode("utf-8") if ftype == "char" else value)
            mav = dialect["__mavlink__"](None, srcSystem=1, srcComponent=1)
            mav.seq = case.seq
            expected = pm(*args).pack(mav).hex()
            assert frames[f"{r.msg.qualified_name}#{j}"] == expected, (r.msg.name, case.cid)
            compared += 1
    assert compared >= 500


@needs_gcc
def test_a_wrong_byte_is_seen(native: Built) -> None:
    """The comparison compares: one uORB case's expected struct with its first byte changed differs."""
    status = next(r for r in native.replays if r.msg.qualified_name == "uorb.BatteryStatus")
    case = status.cases[0]
    tag, line = case.expected[0]
    assert tag == "enc" and line
    changed = f"{(int(line[:2], 16) + 1) % 256:02x}" + line[2:]
    output = [o for o in native.output if o.startswith("uorb.BatteryStatus#0 enc ")]

    def only(expected: str) -> list[Replay]:
        return [Replay(status.kind, status.msg, [replace(case, expected=[(tag, expected)])])]

    assert mismatches(only(line), output) == []
    assert mismatches(only(changed), output) != []


def _tool(*names: str, files: tuple[Path, ...] = ()) -> None:
    """Cross tools (Debian's gcc-s390x-linux-gnu with libc6-dev-s390x-cross, qemu-user,
    gcc-arm-none-eabi): skip without them outside CI; under CI (which installs them) their absence fails."""
    absent = [n for n in names if shutil.which(n) is None] + [str(f) for f in files if not f.is_file()]
    if absent:
        message = f"{', '.join(absent)} not installed"
        if os.environ.get("CI"):
            pytest.fail(message + " (CI installs them: .ci/run)")
        pytest.skip(message)


def test_big_endian_s390x_replays_every_case_as_python(replays: list[Replay], tmp_path: Path) -> None:
    """The same replay, built static for s390x (big-endian) and run under qemu: the bytes on the wire
    and the values decoded do not depend on the host's byte order."""
    _tool("s390x-linux-gnu-gcc", "qemu-s390x", files=(Path("/usr/s390x-linux-gnu/include/stdio.h"),))
    output = compile_and_run(["s390x-linux-gnu-gcc", "-static"], ["qemu-s390x"], tmp_path, replays)
    probe = tmp_path / "order.c"
    probe.write_text("int main(void) { unsigned x = 1; return *(unsigned char *)&x; }\n", encoding="utf-8")
    subprocess.run(
        ["s390x-linux-gnu-gcc", "-static", str(probe), "-o", str(tmp_path / "order")], check=True, timeout=120
    )
    assert subprocess.run(["qemu-s390x", str(tmp_path / "order")], timeout=60).returncode == 0, "not big-endian"
    bad = mismatches(replays, output)
    assert not bad, f"{len(bad)} differences, first:\n" + "\n".join(bad[:10])
    assert len(output) == len(expected_lines(replays))


# what a Cortex-M4 object may leave to the toolchain: libgcc's soft-float helpers and the memset
# gcc makes of a zeroing loop; no heap, no printf, nothing else of a C library
ALLOWED_UNDEFINED = re.compile(r"__aeabi_\w+|memset|memcpy")


def test_cortex_m4_build_without_a_c_library(tmp_path: Path) -> None:
    """Every source builds for a Cortex-M4 (``-Os -mthumb -mcpu=cortex-m4``, the strict warnings) with
    the compiler's freestanding headers only, and calls nothing of a C library."""
    _tool("arm-none-eabi-gcc", "arm-none-eabi-nm", "arm-none-eabi-size")
    for src in SOURCES:
        obj = tmp_path / (src + ".o")
        cc = ["arm-none-eabi-gcc", *FLAGS, "-ffreestanding", "-Os", "-mthumb", "-mcpu=cortex-m4"]
        done = subprocess.run(
            [*cc, "-I", str(GENERATED), "-c", str(GENERATED / src), "-o", str(obj)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert done.returncode == 0, done.stderr[-4000:]
        nm = subprocess.run(
            ["arm-none-eabi-nm", "-u", str(obj)], capture_output=True, text=True, check=True, timeout=60
        )
        undefined = [line.split()[-1] for line in nm.stdout.splitlines() if line.strip()]
        assert [u for u in undefined if not ALLOWED_UNDEFINED.fullmatch(u)] == [], src
        size = subprocess.run(["arm-none-eabi-size", str(obj)], capture_output=True, text=True, check=True, timeout=60)
        text, data, bss = (int(v) for v in size.stdout.splitlines()[1].split()[:3])
        assert text > 0 and data == 0 and bss == 0, (src, size.stdout)  # no state: every call is re-entrant


@needs_gcc
def test_readme_example_runs_as_python_says(tmp_path: Path) -> None:
    """generated/c/README.md's example (decode a DroneCAN BatteryInfo, convert it with the px4 policy)
    compiles with the strict flags and prints what the Python package makes of the same payload: the
    same battery_status figures and the same loss report."""
    import generated.convert as converters
    from generated.dronecan.uavcan.equipment.power import BatteryInfo

    readme = (GENERATED / "README.md").read_text(encoding="utf-8")
    example = readme.split("```c\n", 1)[1].split("```", 1)[0]
    assert 15 <= len(example.strip().splitlines()) <= 35
    (tmp_path / "example.c").write_text(example, encoding="utf-8")
    exe = tmp_path / "example"
    sources = [str(GENERATED / "dronecan.c"), str(GENERATED / "convert.c")]
    cc = ["gcc", *FLAGS, "-I", str(GENERATED), str(tmp_path / "example.c"), *sources]
    subprocess.run([*cc, "-o", str(exe)], check=True, timeout=300)
    ran = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60, check=True)
    block = example.split("payload[] = {", 1)[1].split("}", 1)[0]
    payload = bytes(int(b, 16) for b in block.replace(",", " ").split())
    report = converters.LossReport()
    status = converters.converter("dronecan", "uorb")(BatteryInfo.decode(payload), policy="px4", report=report)
    head = (
        f"{status.voltage_v:.2f} V, {status.current_a:.2f} A, {status.temperature:.2f} degC, "
        f"remaining {status.remaining:.2f}, warning {status.warning}"
    )
    assert ran.stdout.splitlines() == [head, *(f"{e.kind} {e.field}" for e in report.entries)]
    assert head == "16.80 V, -1.50 A, 25.10 degC, remaining 0.87, warning 0"


@needs_gcc
def test_sanitizers_find_nothing(replays: list[Replay], tmp_path: Path) -> None:
    """The replay under AddressSanitizer and UndefinedBehaviorSanitizer (every report fatal): no
    out-of-bounds access, no signed overflow, no shift beyond a width, no misaligned access."""
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n", encoding="utf-8")
    sanitize = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g"]
    if subprocess.run(["gcc", *sanitize, str(probe), "-o", str(tmp_path / "probe")], timeout=120).returncode != 0:
        pytest.skip("gcc's sanitizer runtimes (libasan, libubsan) not installed")
    output = compile_and_run(["gcc", *sanitize], [], tmp_path, replays)
    bad = mismatches(replays, output)
    assert not bad, f"{len(bad)} differences, first:\n" + "\n".join(bad[:10])


@needs_gcc
def test_c_frames_equal_mavgens_c(native: Built, tmp_path: Path) -> None:
    """Every MAVLink 2 frame the C writes equals the frame of mavgen's own C (pymavlink's generator,
    run at test time on the same XML into the temp dir) for the same struct values."""
    from pymavlink.generator import mavgen

    frames = {}
    for line in native.output:
        key, _, rest = line.partition(" ")
        tag, _, rest = rest.partition(" ")
        if tag == "frame":
            frames[key] = rest
    compared = 0
    for xml in sorted((bundled_schemas() / "mavlink").glob("*.xml")):
        out = tmp_path / xml.stem
        opts = mavgen.Opts(str(out), wire_protocol="2.0", language="C", validate=False)
        assert mavgen.mavgen(opts, [str(xml)])
        mine = [
            r
            for r in native.replays
            if r.kind == "mavlink" and (out / xml.stem / f"mavlink_msg_{r.msg.name.lower()}.h").is_file()
        ]
        assert mine, xml.name
        lines = [f'#include "{xml.stem}/mavlink.h"', "#include <math.h>", "#include <stdio.h>", ""]
        for r in mine:
            low = r.msg.name.lower()
            lines.append(f"static const mavlink_{low}_t given_{low}[] = {{")
            lines += [f"{c.given}," for c in r.cases]
            lines.append("};")
        lines += [
            "int main(void) {",
            "mavlink_message_t msg;",
            "uint8_t buf[MAVLINK_MAX_PACKET_LEN];",
            "size_t j, i, n;",
        ]
        for r in mine:
            low = r.msg.name.lower()
            lines += [
                f"for (j = 0; j < {len(r.cases)}u; j++) {{",
                "mavlink_get_channel_status(MAVLINK_COMM_0)->current_tx_seq = (uint8_t)(j % 256u);",
                f"mavlink_msg_{low}_encode(1, 1, &msg, &given_{low}[j]);",
                "n = mavlink_msg_to_send_buffer(buf, &msg);",
                f'printf("{r.msg.qualified_name}#%lu ", (unsigned long)j);',
                'for (i = 0; i < n; i++) { printf("%02x", buf[i]); }',
                'printf("\\n");',
                "}",
            ]
        lines += ["return 0;", "}", ""]
        (out / "main.c").write_text("\n".join(lines), encoding="utf-8")
        exe = out / "mavgen_frames"
        done = subprocess.run(
            ["gcc", "-w", "-I", str(out), str(out / "main.c"), "-o", str(exe)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert done.returncode == 0, done.stderr[-4000:]
        ran = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, check=True)
        records = {f"{r.msg.qualified_name}#{j}": c.record for r in mine for j, c in enumerate(r.cases)}
        for line in ran.stdout.splitlines():
            key, _, theirs = line.partition(" ")
            if records[key].get("mavlink_version", 2) != 2:
                continue  # HEARTBEAT: mavgen's C writes 2 ("filled in by the MAVLink library"), whatever is given
            assert frames[key] == theirs, key
            compared += 1
    assert compared >= 500
