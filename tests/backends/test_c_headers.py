"""The generated C headers compile as strict C99 (and as C++ through the extern "C" guards), and the
committed generated/c/ is what the backend renders from the bundled schemas."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.backends.c import render_library
from codegen.frontends.loader import load

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]


def test_committed_library_is_fresh() -> None:
    files = render_library(load([bundled_schemas()]))
    assert files, "no C files rendered"
    for rel, text in files.items():
        assert (GENERATED / rel).read_text(encoding="utf-8") == text, rel


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_every_header_compiles_as_strict_c99(tmp_path: Path) -> None:
    main = tmp_path / "main.c"
    main.write_text(
        '#include "battgen.h"\n'
        "int main(void) {\n"
        "  battgen_dronecan_uavcan_equipment_power_BatteryInfo info;\n"
        "  info.voltage = 16.8f;\n"
        "  return BATTGEN_MAVLINK_BATTERY_STATUS_CRC_EXTRA == 154u && info.voltage > 0.0f ? 0 : 1;\n"
        "}\n"
    )
    exe = tmp_path / "main"
    subprocess.run(["gcc", *FLAGS, "-I", str(GENERATED), str(main), "-o", str(exe)], check=True, timeout=120)
    assert subprocess.run([str(exe)], timeout=30).returncode == 0


@pytest.mark.skipif(shutil.which("g++") is None, reason="g++ not installed")
def test_headers_compile_as_cpp(tmp_path: Path) -> None:
    main = tmp_path / "main.cpp"
    main.write_text('#include "battgen.h"\nint main() { return 0; }\n')
    subprocess.run(
        [
            "g++",
            "-std=c++11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-I",
            str(GENERATED),
            str(main),
            "-o",
            str(tmp_path / "m"),
        ],
        check=True,
        timeout=120,
    )


def test_cli_writes_and_checks_a_c_library(tmp_path: Path) -> None:
    from codegen.cli.main import main

    out = tmp_path / "clib"
    assert main(["generate", "--lang", "c", "-o", str(out)]) == 0
    assert (out / "battgen.h").is_file()
    assert main(["generate", "--lang", "c", "-o", str(out), "--check"]) == 0
    (out / "battgen.h").write_text("/* edited */\n")
    assert main(["generate", "--lang", "c", "-o", str(out), "--check"]) == 1
