"""The C library's converters (generated/c/convert.c), proven against the Python package: every
record of ``battgen vectors`` for each mapping the C library converts, and seeded random records
(with and without the optional companion message, the converter inputs given or not), go through
the C converter (compiled once with ``gcc -std=c99 -Wall -Wextra -Wconversion -Werror -pedantic``,
all cases in one run) and through the Python package's converter under the same policy; the
target messages must be the same value by value (floats by their bits, NaN as NaN, so -0.0 and
float16 rounding show) and the loss reports the same entries (kind and field) in the same order."""

from __future__ import annotations

import math
import os
import random
import shutil
import struct
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from c_cases import PRELUDE, _dump_c, _nested, dump, struct_init
from rust_cases import Unrepresentable, _from_json, random_records

import generated.convert as converters
from codegen.apps.conversion.vectors import SIDES, VectorWriter
from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.backends.c.converters import CConverter, c_converters
from codegen.backends.c.types import type_name
from codegen.frontends.loader import load
from codegen.ir import Message, Schema

GENERATED = project_root() / "generated" / "c"
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wconversion", "-Werror", "-pedantic"]
RANDOM = 100  # seeded random records per converter, on top of the vectors
needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")


@dataclass
class Case:
    cid: str
    given: list[str | None]  # C initialiser per source message (None: not received)
    inputs: list[float | None]  # the converter's inputs (dt_s, ...), float32 values
    expected: str  # what the harness must print


def _f32(value: float) -> float:
    rounded: float = struct.unpack("<f", struct.pack("<f", value))[0]
    return rounded


def _as_f32(value: Any) -> Any:
    """A random record with every float made a float32 (the C structs hold float32)."""
    if isinstance(value, float):
        return _f32(value)
    if isinstance(value, list):
        return [_as_f32(v) for v in value]
    if isinstance(value, dict):
        return {k: _as_f32(v) for k, v in value.items()}
    return value


def _losses(report: Any) -> str:
    seen: dict[tuple[str, str], None] = {}
    for e in report.entries:
        seen[(e.kind, e.field)] = None
    return ",".join(f"{kind} {name}" for kind, name in seen)


def _classes(qualified: tuple[str, ...] | list[str]) -> list[Any]:
    import importlib

    out = []
    for q in qualified:
        module = importlib.import_module("generated." + q.rsplit(".", 1)[0])
        out.append(next(c for c in vars(module).values() if getattr(c, "QUALIFIED_NAME", None) == q))
    return out


def _case(
    schema: Schema, conv: CConverter, cid: str, plains: list[dict[str, Any] | None], inputs: list[float | None]
) -> Case:
    """The case of one record, with what the Python converter makes of it (Unrepresentable if C cannot hold it)."""
    sources = [q for q, _, _ in conv.sources]
    objs = [None if p is None else cls.from_dict(p) for cls, p in zip(_classes(sources), plains, strict=True)]
    given = [
        None if o is None else struct_init(schema, schema.message(q), o.to_dict())
        for q, o in zip(sources, objs, strict=True)
    ]
    report = converters.LossReport()
    kwargs = {name: v for name, v in zip(conv.inputs, inputs, strict=True) if v is not None}
    try:
        out = converters.converter(conv.source, conv.target)(*objs, policy=conv.policy, report=report, **kwargs)
    except converters.ConversionError:
        raise Unrepresentable(cid) from None
    outs = out if isinstance(out, tuple) else (out,)
    parts = [dump(schema, schema.message(q), o.to_dict()) for (q, _), o in zip(conv.targets, outs, strict=True)]
    return Case(cid, given, inputs, " | ".join(parts) + " | " + _losses(report))


def _cases(schema: Schema, conv: CConverter) -> tuple[list[Case], int]:
    """(cases, records skipped): every vector's input, then seeded random records."""
    cases: list[Case] = []
    skipped = 0
    aliases = [v for _, v, _ in conv.sources]
    vectors = VectorWriter(conv.source, conv.target, conv.policy).document()["vectors"] if conv.source in SIDES else []
    for vector in vectors:  # type: ignore[attr-defined]
        data = _from_json(vector["input"])
        plains = [data] if len(aliases) == 1 else [data.get(a) for a in aliases]  # type: ignore[union-attr]
        try:
            cases.append(_case(schema, conv, f"vector/{vector['id']}", plains, [None] * len(conv.inputs)))
        except (Unrepresentable, ValueError, TypeError):
            skipped += 1
    rng = random.Random(conv.name)
    streams = [random_records(schema, schema.message(q)) for q, _, _ in conv.sources]
    pools = [[_as_f32(p) for _, p in s] for s in streams]
    for i in range(RANDOM):
        plains = [pool[i % len(pool)] if k == 0 or rng.random() < 0.7 else None for k, pool in enumerate(pools)]
        inputs = [
            None if rng.random() < 0.3 else _f32(rng.choice([0.0, 0.1, 1.0, 2.5, -1.0, 1e3])) for _ in conv.inputs
        ]
        try:
            cases.append(_case(schema, conv, f"random/{i}", plains, inputs))
        except (Unrepresentable, ValueError, TypeError, OverflowError):
            skipped += 1
    return cases, skipped


def _float(v: float | None) -> str:
    assert v is not None
    return "NAN" if math.isnan(v) else float(v).hex() + "f"


def render(schema: Schema, convs: list[tuple[CConverter, list[Case]]]) -> str:
    """The harness: each converter's cases as data, one loop each printing targets and losses."""
    out = [PRELUDE]
    dumped: list[Message] = []
    for conv, _ in convs:
        for q, _v in conv.targets:
            _nested(schema, schema.message(q), dumped)
    for msg in dumped:
        out += _dump_c(schema, msg)
    out += [
        "static void losses(const battgen_loss_report *r) {",
        "size_t i;",
        "for (i = 0; i < r->count; i++) {",
        'if (i) { printf(","); }',
        'printf("%s %s", battgen_loss_kind_name(r->entries[i].kind), r->entries[i].field);',
        "}",
        'if (r->missed) { printf(" missed %lu", (unsigned long)r->missed); }',
        "}",
    ]
    calls = []
    for conv, cases in convs:
        n = conv.name
        for k, (q, _v, _o) in enumerate(conv.sources):
            t = type_name(q)
            rows = [f"{g or '{0}'}, /* {c.cid} */" for c, g in ((c, c.given[k]) for c in cases)]
            out += [f"static const {t} {n}_in{k}[] = {{", *rows, "};"]
            out.append(
                f"static const int {n}_has{k}[] = {{" + ", ".join("1" if c.given[k] else "0" for c in cases) + "};"
            )
        for k in range(len(conv.inputs)):
            out.append(
                f"static const float {n}_x{k}[] = {{"
                + ", ".join(_float(c.inputs[k]) if c.inputs[k] is not None else "0.0f" for c in cases)
                + "};"
            )
            out.append(
                f"static const int {n}_hx{k}[] = {{"
                + ", ".join("0" if c.inputs[k] is None else "1" for c in cases)
                + "};"
            )
        args = [f"{n}_has{k}[j] ? &{n}_in{k}[j] : NULL" for k in range(len(conv.sources))]
        args += [f"{n}_hx{k}[j] ? &{n}_x{k}[j] : NULL" for k in range(len(conv.inputs))]
        decl = []
        for k, (q, _v) in enumerate(conv.targets):
            decl.append(f"{type_name(q)} out{k};")
            args.append(f"&out{k}")
        dumps = [f'dump_{type_name(q)}(&out{k}); printf(" | ");' for k, (q, _v) in enumerate(conv.targets)]
        out += [
            f"static void run_{n}(void) {{",
            "size_t j;",
            "static battgen_loss_report rep;",
            f"for (j = 0; j < {len(cases)}u; j++) {{",
            *decl,
            "battgen_loss_clear(&rep);",
            f"{n}({', '.join(args)}, &rep);",
            f'printf("{n}#%lu ", (unsigned long)j);',
            *dumps,
            "losses(&rep);",
            'printf("\\n");',
            "}",
            "}",
        ]
        calls.append(f"run_{n}();")
    out += ["int main(void) {", "(void)pd; (void)hex; (void)pstr; (void)problems;", *calls, "return 0;", "}", ""]
    return "\n".join(out)


@dataclass(frozen=True)
class Run:
    convs: list[tuple[CConverter, list[Case]]]
    skipped: int
    output: dict[str, str]
    harness: str


def build_and_run(cc: list[str], runner: list[str], tmp: Path, harness: str) -> dict[str, str]:
    """convert.c built by ``cc`` with the strict flags, the harness linked to it, run (through
    ``runner``: an emulator, or nothing); the harness's lines by case."""
    (tmp / "main.c").write_text(harness, encoding="utf-8")
    obj = tmp / "convert.o"
    done = subprocess.run(
        [*cc, *FLAGS, "-I", str(GENERATED), "-c", str(GENERATED / "convert.c"), "-o", str(obj)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    exe = tmp / "convert_replay"
    loose = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-Wno-missing-braces", "-Wno-missing-field-initializers"]
    link = [*cc, *loose, "-I", str(GENERATED), str(tmp / "main.c"), str(obj), "-lm", "-o", str(exe)]
    done = subprocess.run(link, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-4000:]
    ran = subprocess.run([*runner, str(exe)], capture_output=True, text=True, timeout=300, check=False)
    assert ran.returncode == 0, ran.stderr[-4000:]
    return dict(line.split(" ", 1) for line in ran.stdout.splitlines())


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Run:
    if shutil.which("gcc") is None:
        pytest.skip("gcc not installed")
    schema = load([bundled_schemas()])
    made, _, _ = c_converters(schema)
    convs = []
    skipped = 0
    for conv in made:
        cases, lost = _cases(schema, conv)
        convs.append((conv, cases))
        skipped += lost
    harness = render(schema, convs)
    output = build_and_run(["gcc"], [], tmp_path_factory.mktemp("cconv"), harness)
    return Run(convs, skipped, output, harness)


def differences(run: Run, output: dict[str, str]) -> list[str]:
    bad = []
    for conv, cases in run.convs:
        for j, case in enumerate(cases):
            got = output.get(f"{conv.name}#{j}")
            if got != case.expected:
                bad.append(f"{conv.name} {case.cid}:\n  C:      {got}\n  Python: {case.expected}")
    return bad


@needs_gcc
def test_dronecan_to_uorb_is_in_c_under_both_policies(run: Run) -> None:
    """DroneCAN BatteryInfo (+ BatteryInfoAux) -> uORB battery_status: strict (through the concepts)
    and px4 (PX4's uavcan bridge), and each converter meets its vectors and random records."""
    names = {conv.name for conv, _ in run.convs}
    assert {"battgen_convert_dronecan_to_uorb_strict", "battgen_convert_dronecan_to_uorb_px4"} <= names
    for conv, cases in run.convs:
        vectors = [c for c in cases if c.cid.startswith("vector/")]
        assert len(cases) - len(vectors) >= RANDOM // 2, (conv.name, len(cases), run.skipped)
        assert len(vectors) >= 40 or conv.source not in SIDES, conv.name


@needs_gcc
def test_c_converts_every_case_as_python(run: Run) -> None:
    bad = differences(run, run.output)
    compared = sum(len(cases) for _, cases in run.convs)
    assert not bad, f"{len(bad)} of {compared} differ, first:\n" + "\n".join(bad[:5])
    lines = " ".join(c.expected for _, cases in run.convs for c in cases)
    for kind in ("unknown", "dropped", "clamped", "rounded"):  # the cases reach every kind the converters report
        assert f"{kind} " in lines, kind
    assert "=nan;" in lines and "=80000000;" in lines  # NaN and -0.0 among the values compared


@needs_gcc
def test_sanitizers_find_nothing_in_the_converters(run: Run, tmp_path: Path) -> None:
    """The same cases under AddressSanitizer and UndefinedBehaviorSanitizer (every report fatal)."""
    sanitize = ["gcc", "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g"]
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n", encoding="utf-8")
    if subprocess.run([*sanitize, str(probe), "-o", str(tmp_path / "probe")], timeout=120).returncode != 0:
        pytest.skip("gcc's sanitizer runtimes not installed")
    bad = differences(run, build_and_run(sanitize, [], tmp_path, run.harness))
    assert not bad, "\n".join(bad[:5])


def test_big_endian_s390x_converts_as_python(run: Run, tmp_path: Path) -> None:
    """The same cases built static for s390x (big-endian) and run under qemu."""
    tools = ("s390x-linux-gnu-gcc", "qemu-s390x")
    absent = [t for t in tools if shutil.which(t) is None]
    if absent:
        if os.environ.get("CI"):
            pytest.fail(f"{', '.join(absent)} not installed (CI installs them: .ci/run)")
        pytest.skip(f"{', '.join(absent)} not installed")
    bad = differences(run, build_and_run(["s390x-linux-gnu-gcc", "-static"], ["qemu-s390x"], tmp_path, run.harness))
    assert not bad, "\n".join(bad[:5])


@needs_gcc
def test_a_changed_value_is_seen(run: Run) -> None:
    """The comparison compares: a case's expected line with one float's bits changed differs from C's."""
    conv, cases = next((c, k) for c, k in run.convs if c.name == "battgen_convert_dronecan_to_uorb_px4")
    line = cases[0].expected
    changed = line.replace("voltage_v=", "voltage_v=1", 1)
    assert changed != line and run.output[f"{conv.name}#0"] == line != changed


def test_the_readme_lists_the_converters_and_what_is_left_out() -> None:
    schema = load([bundled_schemas()])
    made, _, left = c_converters(schema)
    readme = (GENERATED / "README.md").read_text(encoding="utf-8")
    assert all(f"`{c.name}`" in readme for c in made)
    assert all(why in readme for why in left)
    assert bool(left) != ("Every converter of the Python package between formats" in readme)
