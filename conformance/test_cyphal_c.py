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
from typing import Any

import pytest
from c_cases import PRELUDE, _print, value_init
from cyphal_native_cases import TypeCases, all_cases, definition_cases, dump, has_nan
from rust_cases import Unrepresentable

from codegen.apps.schemas.package import project_root
from codegen.backends.c.render import render_library
from codegen.backends.c.types import ident, type_name
from codegen.ir import ArrayType, CompositeType, FieldType, Message, Schema

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
LOOSE = ["-Wno-missing-field-initializers", "-Wno-missing-braces", "-Wno-overlength-strings", "-Wno-unused-function"]


def _bytes(data: bytes) -> str:
    return '(const uint8_t *)"' + "".join(f"\\x{b:02x}" for b in data) + '"'


def _assigns(schema: Schema, t: FieldType, v: Any, target: str) -> list[str]:
    """The C statements setting ``target`` (zeroed) to the plain value ``v`` of type ``t``."""
    if isinstance(t, CompositeType):
        msg = schema.message(t.name)
        fields = [(k, f) for k, f in enumerate(msg.fields) if not f.is_padding and f.name in v]
        head = [f"{target}.union_tag = {fields[0][0]};"] if msg.is_union else []
        return head + [
            line for _, f in fields for line in _assigns(schema, f.type, v[f.name], f"{target}.{ident(f.name)}")
        ]
    if isinstance(t, ArrayType):
        out = [line for i, e in enumerate(v) for line in _assigns(schema, t.element, e, f"{target}[{i}]")]
        return [*out, f"{target}_len = {len(v)};"] if t.dynamic else out
    return [f"{target} = {value_init(schema, t, v, True)[0]};"]


def _dump_c(schema: Schema, msg: Message) -> list[str]:
    """The program's ``dump_<type>``: every field as ``cyphal_native_cases.dump`` prints it."""
    t = type_name(msg.qualified_name)
    lines = [f"static void dump_{t}(const {t} *m) {{", "size_t i = 0;", "(void)i; (void)m;"]
    fields = [f for f in msg.fields if not f.is_padding]
    if msg.is_union:
        lines += ['printf("tag=%u;", (unsigned)m->union_tag);', "switch (m->union_tag) {"]
    for k, f in enumerate(fields):
        name = f"m->{ident(f.name)}"
        if msg.is_union:
            lines.append(f"case {k}: {{")
        lines.append(f'printf("{f.name}=");')
        if isinstance(f.type, ArrayType):
            count = f"{name}_len" if f.type.dynamic else f"{f.type.capacity}u"
            lines += ['printf("[");', f"for (i = 0; i < (size_t){count}; i++) {{", 'if (i) { printf(","); }']
            lines += [_print(schema, f.type.element, f"{name}[i]"), "}", 'printf("]");']
        else:
            lines.append(_print(schema, f.type, name))
        lines.append('printf(";");')
        if msg.is_union:
            lines += ["break;", "}"]
    if msg.is_union:
        lines += ["default:", "break;", "}"]
    return [*lines, "}"]


def _program(schema: Schema, cases: list[TypeCases]) -> tuple[str, list[str]]:
    """The C program and the lines it must print."""
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
        buffer = f"{t.upper()}_BUFFER_BYTES"
        lines += [
            f"static void enc_{t}(const {t} *m, unsigned long j) {{",
            f"static uint8_t buf[{buffer}];",
            "size_t n;",
            f'printf("enc {c.name}#%lu ", j);',
            f"if ({t}_encode(m, false, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }}",
            'else { printf("error"); }',
            'printf("\\n");',
            f'printf("hdr {c.name}#%lu ", j);',
            f"if ({t}_encode(m, true, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }}",
            f'else {{ printf("%s", {t.upper()}_SEALED ? "sealed" : "error"); }}',
            'printf("\\n");',
            "}",
        ]
        given = 0
        body = []
        for v in c.values:
            try:
                sets = _assigns(schema, CompositeType(c.name), v.given, "m")
            except Unrepresentable:
                assert has_nan(v.given), v.given  # only a NaN payload C's NAN does not spell is left out
                continue
            body += ["{", f"static {t} m;", "battgen_zero(&m, sizeof m);", *sets, f"enc_{t}(&m, {given}u);", "}"]
            expected.append(f"enc {c.name}#{given} {v.wire.hex()}")
            expected.append(f"hdr {c.name}#{given} {v.headed.hex() if v.headed is not None else 'sealed'}")
            given += 1
        inputs = [f"{{{_bytes(r.data)}, {len(r.data)}u, {'true' if r.header else 'false'}}}," for r in c.reads]
        lines += [f"static const input read_{t}[] = {{", *inputs, "};"]
        for k, r in enumerate(c.reads):
            if r.decoded is None:
                expected.append(f"dec {c.name}#{k} error")
            else:
                again = r.again.hex() if r.again is not None else "-"
                expected.append(f"dec {c.name}#{k} {dump(schema, c.msg, r.decoded)} {again}")
        lines += [
            f"static void run_{t}(void) {{",
            f"static uint8_t buf[{buffer}];",
            f"static {t} m;",
            "size_t j, n;",
            *body,
            f"for (j = 0; j < {len(c.reads)}u; j++) {{",
            f'printf("dec {c.name}#%lu ", (unsigned long)j);',
            f"if ({t}_decode(read_{t}[j].p, read_{t}[j].n, read_{t}[j].header, &m) != BATTGEN_OK) {{",
            'printf("error\\n");',
            "continue;",
            "}",
            f"dump_{t}(&m);",
            'printf(" ");',
            f"if ({t}_encode(&m, false, buf, &n) == BATTGEN_OK) {{ hex(buf, n); }}",
            'else { printf("error"); }',
            'printf("\\n");',
            "}",
            "}",
        ]
        calls.append(f"run_{t}();")
    lines += ["int main(void) {", *calls, "return 0;", "}", ""]
    return "\n".join(lines), expected


@pytest.fixture(scope="module")
def program(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str], list[TypeCases]]:
    schema, cases = all_cases()
    text, expected = _program(schema, cases)
    folder = tmp_path_factory.mktemp("cyphal_c")
    (folder / "main.c").write_text(text, encoding="utf-8")
    return folder, expected, cases


def _run(folder: Path, cc: list[str], runner: list[str], name: str, library: Path = GENERATED) -> list[str]:
    exe = folder / name
    sources = [str(folder / "main.c"), str(library / "cyphal.c")]
    done = subprocess.run(
        [*cc, *FLAGS, *LOOSE, "-I", str(library), *sources, "-o", str(exe)],
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
    assert names == {c.name for c in cases}


def _needs(*tools: str) -> None:
    absent = [t for t in tools if shutil.which(t) is None]
    if absent:
        if os.environ.get("CI"):
            pytest.fail(f"{', '.join(absent)} not installed (CI installs them: .ci/run)")
        pytest.skip(f"{', '.join(absent)} not installed")


# AddressSanitizer and UBSan: a read or write out of bounds, or undefined arithmetic, ends the program
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]


def test_c_cyphal_codecs_are_pydsdls(program: tuple[Path, list[str], list[TypeCases]]) -> None:
    """Natively, under the sanitizers (the bytes read include short, extended, bad-header and random ones)."""
    _needs("gcc")
    folder, expected, cases = program
    got = _run(folder, ["gcc", *SANITIZE], [], "native")
    compare(expected, got, cases)
    assert len(cases) == 19
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


def test_c_cyphal_unions_and_nested_delimited_types_are_pydsdls(tmp_path: Path) -> None:
    """What the bundled types lack (cyphal_native_cases.DEFINITIONS): a union's tag and held field, a
    delimited type nested alone and in an array behind its delimiter header; the library rendered for them."""
    _needs("gcc")
    schema, cases = definition_cases(tmp_path / "dsdl")
    library = tmp_path / "c"
    for rel, text in render_library(schema).items():
        (library / rel).parent.mkdir(parents=True, exist_ok=True)
        (library / rel).write_text(text, encoding="utf-8")
    text, expected = _program(schema, cases)
    (tmp_path / "main.c").write_text(text, encoding="utf-8")
    got = _run(tmp_path, ["gcc", *SANITIZE], [], "definitions", library)
    compare(expected, got, cases)
    assert any(re.search(r"pick=\{tag=2;inner=\{a=\d+;b=\[[0-9a-f,]+\];\};\}", line) for line in got)
