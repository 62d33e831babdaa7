"""The C library's DroneCAN bytes against pydronecan's own encoder, directly: for every bundled DroneCAN
type, seeded random records (values beyond a field's width, float16 rounding and saturation, arrays
empty to full, nested types) are set on pydronecan's object for the type (``dronecan.TYPENAMES``,
the DSDL tree it ships) and on the C struct, and both payloads -- with the tail array optimisation
and without (CAN FD) -- must be the same bytes. All records go through one C program."""

from __future__ import annotations

import random
import shutil
import subprocess
from typing import Any

import pytest
from c_cases import struct_init
from rust_cases import Unrepresentable, random_records

from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.backends.c.types import type_name
from codegen.frontends.loader import load
from codegen.ir import ArrayType, CompositeType, Message, Schema

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
RECORDS = 200  # per type


def _set(schema: Schema, msg: Message, obj: Any, plain: dict[str, Any]) -> None:
    """The record's values on pydronecan's object (nested types field by field)."""
    for f in msg.fields:
        if f.is_padding or f.name not in plain:
            continue
        value = plain[f.name]
        if isinstance(f.type, CompositeType):
            _set(schema, schema.message(f.type.name), getattr(obj, f.name), value)
        elif isinstance(f.type, ArrayType):
            setattr(obj, f.name, list(value))
        else:
            setattr(obj, f.name, value)


def _reference(schema: Schema, msg: Message, plain: dict[str, Any]) -> tuple[str, str]:
    import dronecan
    from dronecan import transport

    obj = dronecan.TYPENAMES[msg.qualified_name.removeprefix("dronecan.")]()
    _set(schema, msg, obj, plain)
    tao = bytes(transport.bytes_from_bits(obj._pack(True))).hex()
    fd = bytes(transport.bytes_from_bits(obj._pack(False))).hex()
    return tao, fd


def _records(schema: Schema, msg: Message) -> list[dict[str, Any]]:
    rng = random.Random(msg.qualified_name + "/pydronecan")
    pool = [p for _, p in random_records(schema, msg)]
    out = []
    for i in range(RECORDS):
        plain = dict(pool[i % len(pool)])
        # mix fields across the pool's records, so every field meets every kind of value
        for f in msg.fields:
            if not f.is_padding and rng.random() < 0.5:
                plain[f.name] = rng.choice(pool)[f.name]
        out.append(plain)
    return out


@pytest.fixture(scope="module")
def compared(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, str, str, str]]:
    """(case, what pydronecan writes with TAO / without, the C program's line)."""
    pytest.importorskip("dronecan")
    if shutil.which("gcc") is None:
        pytest.skip("gcc not installed")
    schema = load([bundled_schemas()])
    lines = ['#include "battgen.h"', "#include <math.h>", "#include <stdio.h>", ""]
    calls = []
    expected: list[tuple[str, str, str]] = []
    for msg in schema.messages:
        if msg.dronecan is None or msg.dronecan.union:
            continue
        t = type_name(msg.qualified_name)
        rows = []
        for j, plain in enumerate(_records(schema, msg)):
            try:
                given = struct_init(schema, msg, plain)
                tao, fd = _reference(schema, msg, plain)
            except (Unrepresentable, ValueError, TypeError, OverflowError):
                continue
            rows.append(given)
            expected.append((f"{msg.qualified_name}#{len(rows) - 1}", tao, fd))
            del j
        lines += [f"static const {t} given_{t}[] = {{", *(f"{r}," for r in rows), "};"]
        lines += [
            f"static void run_{t}(void) {{",
            f"uint8_t buf[{t.upper()}_MAX_BYTES];",
            "size_t j, i, n;",
            f"for (j = 0; j < {len(rows)}u; j++) {{",
            f'printf("{msg.qualified_name}#%lu ", (unsigned long)j);',
            f"if ({t}_encode(&given_{t}[j], true, buf, &n) != BATTGEN_OK) {{ n = 0; }}",
            'for (i = 0; i < n; i++) { printf("%02x", buf[i]); }',
            'printf(" ");',
            f"if ({t}_encode(&given_{t}[j], false, buf, &n) != BATTGEN_OK) {{ n = 0; }}",
            'for (i = 0; i < n; i++) { printf("%02x", buf[i]); }',
            'printf("\\n");',
            "}",
            "}",
        ]
        calls.append(f"run_{t}();")
    lines += ["int main(void) {", *calls, "return 0;", "}", ""]
    tmp = tmp_path_factory.mktemp("dcref")
    (tmp / "main.c").write_text("\n".join(lines), encoding="utf-8")
    exe = tmp / "dronecan_reference"
    cc = ["gcc", *FLAGS, "-Wno-missing-field-initializers", "-Wno-missing-braces", "-I", str(GENERATED)]
    done = subprocess.run(
        [*cc, str(tmp / "main.c"), str(GENERATED / "dronecan.c"), "-o", str(exe)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, [line[:300] for line in done.stderr.splitlines() if "error" in line][:5]
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, check=True).stdout
    got = dict(line.split(" ", 1) for line in out.splitlines())
    return [(key, tao, fd, got.get(key, "<missing>")) for key, tao, fd in expected]


def test_every_bundled_dronecan_type_is_compared(compared: list[tuple[str, str, str, str]]) -> None:
    schema = load([bundled_schemas()])
    types = {m.qualified_name for m in schema.messages if m.dronecan is not None and not m.dronecan.union}
    counts = {t: sum(1 for key, *_ in compared if key.split("#")[0] == t) for t in types}
    assert all(n >= RECORDS // 2 for n in counts.values()), counts


def test_c_bytes_equal_pydronecans(compared: list[tuple[str, str, str, str]]) -> None:
    bad = [
        f"{key}:\n  C:          {got}\n  pydronecan: {tao} {fd}"
        for key, tao, fd, got in compared
        if got != f"{tao} {fd}"
    ]
    assert not bad, f"{len(bad)} of {len(compared)} differ, first:\n" + "\n".join(bad[:5])
