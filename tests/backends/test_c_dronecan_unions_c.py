"""DroneCAN unions in the C library: small DSDL definitions written here (a union of an empty type, a
number, an array and a float16; a union as the last field of a structure, where the tail array
optimisation reaches the held array; a three-field union, whose fourth tag names nothing) rendered
as C, built with the strict flags and run: every branch's bytes equal pydronecan's for the same
definitions, with and without the tail array optimisation; the bytes read back give the same branch
and re-encode to the same bytes; a tag naming no field is refused."""

from __future__ import annotations

import shutil
import subprocess
from typing import Any

import pytest

from codegen.backends.c.render import render_library
from codegen.frontends import dsdl

DEFINITIONS = {
    "Nothing.uavcan": "",
    "Pick.uavcan": "@union\ntest.Nothing none\nint16 number\nuint8[<=4] raw\nfloat16 half\n",
    "Holder.uavcan": "uint8 index\ntest.Pick pick\n",
    "Three.uavcan": "@union\nuint8 a\nuint16 b\nfloat32 c\n",
}
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
# (type, C initialiser, the values pydronecan is given: the branch and its value)
CASES: list[tuple[str, str, dict[str, Any]]] = [
    ("Pick", "{.union_tag = 0}", {"none": None}),
    ("Pick", "{.union_tag = 1, .number = -1234}", {"number": -1234}),
    ("Pick", "{.union_tag = 1, .number = 32767}", {"number": 32767}),
    ("Pick", "{.union_tag = 2, .raw_len = 0}", {"raw": []}),
    ("Pick", "{.union_tag = 2, .raw_len = 3, .raw = {1, 2, 255}}", {"raw": [1, 2, 255]}),
    ("Pick", "{.union_tag = 2, .raw_len = 4, .raw = {9, 8, 7, 6}}", {"raw": [9, 8, 7, 6]}),
    ("Pick", "{.union_tag = 3, .half = 1.5f}", {"half": 1.5}),
    ("Pick", "{.union_tag = 3, .half = 70000.0f}", {"half": 70000.0}),
    ("Pick", "{.union_tag = 3, .half = -0.0f}", {"half": -0.0}),
    ("Holder", "{.index = 7, .pick = {.union_tag = 2, .raw_len = 2, .raw = {5, 6}}}", {"index": 7, "raw": [5, 6]}),
    ("Holder", "{.index = 1, .pick = {.union_tag = 1, .number = -2}}", {"index": 1, "number": -2}),
    ("Holder", "{.index = 0, .pick = {.union_tag = 0}}", {"index": 0, "none": None}),
    ("Three", "{.union_tag = 0, .a = 200}", {"a": 200}),
    ("Three", "{.union_tag = 1, .b = 65535}", {"b": 65535}),
    ("Three", "{.union_tag = 2, .c = 3.25f}", {"c": 3.25}),
]


def _reference(types: dict[str, Any], name: str, values: dict[str, Any], tao: bool) -> str:
    from dronecan import transport

    obj = transport.CompoundValue(types[f"test.{name}"])
    target = obj
    if name == "Holder":
        obj.index = values["index"]
        target = obj.pick
    for key, value in values.items():
        if key == "index" and name == "Holder":
            continue
        if value is None:
            transport.switch_union_field(target, key)
        elif isinstance(value, list):
            setattr(target, key, value)
        else:
            setattr(target, key, value)
    return bytes(transport.bytes_from_bits(obj._pack(tao))).hex()


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[str], dict[str, Any]]:
    pydronecan = pytest.importorskip("dronecan")
    if shutil.which("gcc") is None:
        pytest.skip("gcc not installed")
    base = tmp_path_factory.mktemp("c_union")
    folder = base / "dsdl" / "test"
    folder.mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (folder / name).write_text(text)
    schema = dsdl.parse_dir(base / "dsdl")
    lib = base / "c"
    for rel, text in render_library(schema).items():
        (lib / rel).parent.mkdir(parents=True, exist_ok=True)
        (lib / rel).write_text(text, encoding="utf-8")
    prefix = "battgen_" + next(m.qualified_name for m in schema.messages if m.name == "Pick").replace(".", "_")[:-4]
    lines = [
        '#include "battgen.h"',
        "#include <math.h>",
        "#include <stdio.h>",
        "",
        "static void hex(const uint8_t *p, size_t n) {",
    ]
    lines += ["size_t i;", 'for (i = 0; i < n; i++) { printf("%02x", p[i]); }', "}", "int main(void) {"]
    lines += ["uint8_t buf[64], again[64];", "size_t n, m;", "int e;"]
    for j, (name, given, _) in enumerate(CASES):
        t = prefix + name
        lines += [
            "{",
            f"const {t} g = {given};",
            f"{t} back;",
            f"e = (int){t}_encode(&g, true, buf, &n);",
            'printf("%d ", e); hex(buf, n); printf(" ");',
            f"e = (int){t}_encode(&g, false, buf, &n);",
            'printf("%d ", e); hex(buf, n); printf(" ");',
            f"e = (int){t}_encode(&g, true, buf, &n);",
            f"e = (int){t}_decode(buf, n, true, &back);",
            f"m = 0; if (e == 0) {{ e = (int){t}_encode(&back, true, again, &m); }}",
            f'printf("%d %d %d\\n", e, (int)back.{"pick." if name == "Holder" else ""}union_tag, (int)(m == n));',
            "}",
        ]
        del j
    t = prefix + "Three"
    lines += [
        "{",
        f"{t} back;",
        "const uint8_t bad[] = {0xC0u, 0u, 0u, 0u, 0u};",
        f'printf("tag %d\\n", (int){t}_decode(bad, sizeof bad, true, &back));',
        f"{t} wrong = {{0}};",
        "wrong.union_tag = 3u;",
        f'printf("put %d\\n", (int){t}_encode(&wrong, true, buf, &n));',
        "}",
        "{",
        f"{prefix}Pick p = {{0}};",
        "battgen_problem probs[8];",
        "p.union_tag = 1u;",
        "p.half = NAN;",
        "p.raw_len = 9u;",
        f'printf("held %lu ", (unsigned long){prefix}Pick_validate(&p, probs, 8u));',
        "p.union_tag = 3u;",
        f"n = {prefix}Pick_validate(&p, probs, 8u);",
        'printf("%lu %s\\n", (unsigned long)n, probs[0].field);',
        "}",
        "return 0;",
        "}",
        "",
    ]
    (base / "main.c").write_text("\n".join(lines), encoding="utf-8")
    exe = base / "unions"
    cc = ["gcc", *FLAGS, "-I", str(lib), str(base / "main.c"), str(lib / "dronecan.c"), "-o", str(exe)]
    done = subprocess.run(cc, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60, check=True).stdout.splitlines()
    types = {t.full_name: t for t in pydronecan.dsdl.parse_namespaces([str(folder)])}
    return out, types


def test_every_branch_is_pydronecans_bytes(built: tuple[list[str], dict[str, Any]]) -> None:
    out, types = built
    for line, (name, given, values) in zip(out, CASES, strict=False):
        tao_err, tao, fd_err, fd, *_ = line.split(" ")
        assert (tao_err, fd_err) == ("0", "0"), (name, given)
        assert tao == _reference(types, name, values, True), (name, given)
        assert fd == _reference(types, name, values, False), (name, given)


def test_the_bytes_read_back_hold_the_same_branch(built: tuple[list[str], dict[str, Any]]) -> None:
    out, _ = built
    for line, (name, given, _) in zip(out, CASES, strict=False):
        *_, err, tag, same = line.split(" ")
        expected_tag = given.split("union_tag = ", 1)[1].split(",")[0].split("}")[0]
        assert (err, tag, same) == ("0", expected_tag, "1"), (name, given)


def test_a_tag_naming_no_field_is_refused(built: tuple[list[str], dict[str, Any]]) -> None:
    out, _ = built
    assert out[len(CASES) : len(CASES) + 2] == ["tag 10", "put 10"]  # BATTGEN_ERR_TAG both ways


def test_the_validator_checks_the_held_branch_only(built: tuple[list[str], dict[str, Any]]) -> None:
    """As the Python validator: a NaN half and an overlong raw are no problem while number is held."""
    out, _ = built
    assert out[len(CASES) + 2] == "held 0 1 half"
