"""The C library's Cyphal codecs (generated/c/cyphal.c) against pydsdl and the generated Python package.

For every bundled Cyphal type, the cases of ``cyphal_native_cases`` (hypothesis-drawn values and values
beyond each cast's range; bytes truncated, extended, behind right, extended and too-long delimiter
headers, random) are written as one C program: each value's serialization, with and without the
delimiter header, must be pydsdl's bytes (which the Python package's are, checked there); each byte
string must read as pydsdl reads it (or be refused where pydsdl refuses it), and what was read must
serialize as pydsdl serializes it. Run natively (strict warnings) and built static for big-endian s390x
under qemu; ``cyphal.c`` also builds for a Cortex-M4 without a C library."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from c_cases import PRELUDE, _dump_c, dump, struct_init
from cyphal_native_cases import TypeCases, all_cases, has_nan
from rust_cases import Unrepresentable

from codegen.apps.package import bundled_schemas, project_root
from codegen.backends.c.types import type_name
from codegen.frontends.loader import load
from codegen.ir import ArrayType, CompositeType

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
LOOSE = ["-Wno-missing-field-initializers", "-Wno-missing-braces", "-Wno-overlength-strings", "-Wno-unused-function"]


def _bytes(data: bytes) -> str:
    return '(const uint8_t *)"' + "".join(f"\\x{b:02x}" for b in data) + '"'


def _program(cases: list[TypeCases]) -> tuple[str, list[str]]:
    """The C program and the lines it must print."""
    schema = load([bundled_schemas()])
    lines = [PRELUDE, "typedef struct { const uint8_t *p; size_t n; bool header; } input;", ""]
    expected: list[str] = []
    done: set[str] = set()

    def dumps(name: str) -> None:
        msg = schema.message(name)
        for f in msg.fields:
            inner = f.type
            while isinstance(inner, ArrayType):
                inner = inner.element
            if isinstance(inner, CompositeType) and inner.name not in done:
                dumps(inner.name)  # a dump function before its first use
        if name not in done:
            done.add(name)
            lines.extend(_dump_c(schema, msg))

    calls = []
    for c in cases:
        dumps(c.name)
        t = type_name(c.name)
        given = []
        for v in c.values:
            try:
                init = struct_init(schema, c.msg, v.given)
            except Unrepresentable:
                assert has_nan(v.given), v.given  # only a NaN payload C's NAN does not spell is left out
                continue
            given.append(init)
            expected.append(f"enc {c.name}#{len(given) - 1} {v.wire.hex()}")
            expected.append(f"hdr {c.name}#{len(given) - 1} {v.headed.hex() if v.headed is not None else 'sealed'}")
        lines += [f"static const {t} given_{t}[] = {{", *(f"{g}," for g in given), "};"]
        inputs = [f"{{{_bytes(r.data)}, {len(r.data)}u, {'true' if r.header else 'false'}}}," for r in c.reads]
        lines += [f"static const input read_{t}[] = {{", *inputs, "};"]
        for k, r in enumerate(c.reads):
            if r.decoded is None:
                expected.append(f"dec {c.name}#{k} error")
            else:
                again = r.again.hex() if r.again is not None else "-"
                expected.append(f"dec {c.name}#{k} {dump(schema, c.msg, r.decoded)} {again}")
        buffer = f"{t.upper()}_BUFFER_BYTES"
        lines += [
            f"static void run_{t}(void) {{",
            f"static uint8_t buf[{buffer}];",
            f"static {t} m;",
            "size_t j, n;",
            f"for (j = 0; j < {len(given)}u; j++) {{",
            f'printf("enc {c.name}#%lu ", (unsigned long)j);',
            f"if ({t}_encode(&given_{t}[j], false, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }}",
            'else { printf("error"); }',
            'printf("\\n");',
            f'printf("hdr {c.name}#%lu ", (unsigned long)j);',
            f"if ({t}_encode(&given_{t}[j], true, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }}",
            f'else {{ printf("%s", {t.upper()}_SEALED ? "sealed" : "error"); }}',
            'printf("\\n");',
            "}",
            f"for (j = 0; j < {len(c.reads)}u; j++) {{",
            f'printf("dec {c.name}#%lu ", (unsigned long)j);',
            f"if ({t}_decode(read_{t}[j].p, read_{t}[j].n, read_{t}[j].header, &m) != BATTGEN_OK) {{",
            'printf("error\\n");',
            "continue;",
            "}",
            f"dump_{t}(&m);",
            'printf(" ");',
            f'if ({t}_encode(&m, false, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }} else {{ printf("error"); }}',
            'printf("\\n");',
            "}",
            "}",
        ]
        calls.append(f"run_{t}();")
    lines += ["int main(void) {", *calls, "return 0;", "}", ""]
    return "\n".join(lines), expected


@pytest.fixture(scope="module")
def program(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str], list[TypeCases]]:
    cases = all_cases()
    text, expected = _program(cases)
    folder = tmp_path_factory.mktemp("cyphal_c")
    (folder / "main.c").write_text(text, encoding="utf-8")
    return folder, expected, cases


def _run(folder: Path, cc: list[str], runner: list[str], name: str) -> list[str]:
    exe = folder / name
    done = subprocess.run(
        [
            *cc,
            *FLAGS,
            *LOOSE,
            "-I",
            str(GENERATED),
            str(folder / "main.c"),
            str(GENERATED / "cyphal.c"),
            "-o",
            str(exe),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, [line[:300] for line in done.stderr.splitlines() if "error" in line][:5]
    out = subprocess.run([*runner, str(exe)], capture_output=True, text=True, timeout=300, check=True).stdout
    return out.splitlines()


def compare(expected: list[str], got: list[str], cases: list[TypeCases]) -> None:
    # every line in order; the expected value of a "-" re-encoding (NaN read) is not compared
    assert len(got) == len(expected), (len(got), len(expected))
    bad = []
    for e, g in zip(expected, got, strict=True):
        if e.endswith(" -") and g.rsplit(" ", 1)[0] == e[:-2]:
            continue
        if e != g:
            bad.append(f"expected {e[:300]}\n     got {g[:300]}")
    assert not bad, f"{len(bad)} of {len(expected)} differ, first:\n" + "\n".join(bad[:5])
    names = {line.split(" ")[1].split("#")[0] for line in got}
    assert names == {c.name for c in cases} and len(names) == 19


def _needs(*tools: str) -> None:
    absent = [t for t in tools if shutil.which(t) is None]
    if absent:
        if os.environ.get("CI"):
            pytest.fail(f"{', '.join(absent)} not installed (CI installs them: .ci/run)")
        pytest.skip(f"{', '.join(absent)} not installed")


def test_c_cyphal_codecs_are_pydsdls(program: tuple[Path, list[str], list[TypeCases]]) -> None:
    _needs("gcc")
    folder, expected, cases = program
    got = _run(folder, ["gcc"], [], "native")
    compare(expected, got, cases)
    # the comparison sees a difference: each kind of line is there, and refusals among the reads
    kinds = {line.split(" ")[0] for line in got}
    assert kinds == {"enc", "hdr", "dec"}
    assert sum(1 for line in got if line.endswith(" error")) >= 19
    assert any(re.match(r"hdr \S+ [0-9a-f]{8}", line) for line in got)


def test_c_cyphal_codecs_on_big_endian_s390x(program: tuple[Path, list[str], list[TypeCases]]) -> None:
    _needs("s390x-linux-gnu-gcc", "qemu-s390x")
    folder, expected, cases = program
    got = _run(folder, ["s390x-linux-gnu-gcc", "-static"], ["qemu-s390x"], "s390x")
    compare(expected, got, cases)


def test_c_cyphal_builds_for_cortex_m4_without_a_c_library(tmp_path: Path) -> None:
    _needs("arm-none-eabi-gcc", "arm-none-eabi-nm")
    obj = tmp_path / "cyphal.o"
    cc = ["arm-none-eabi-gcc", *FLAGS, "-ffreestanding", "-Os", "-mthumb", "-mcpu=cortex-m4"]
    subprocess.run(
        [*cc, "-I", str(GENERATED), "-c", str(GENERATED / "cyphal.c"), "-o", str(obj)], check=True, timeout=300
    )
    nm = subprocess.run(["arm-none-eabi-nm", "-u", str(obj)], capture_output=True, text=True, check=True, timeout=60)
    undefined = [line.split()[-1] for line in nm.stdout.splitlines() if line.strip()]
    assert [u for u in undefined if not re.fullmatch(r"__aeabi_\w+|memset|memcpy", u)] == []
