"""The Rust crate's converter replay, written by the Python side at test time: the cases the C
library's converters are proven on (tests/backends/test_c_converters.py: every vector's input and
100 seeded random records per converter, with and without the optional message and the inputs),
each with what the generated Python package's converter makes of it under the same policy, printed
as the C harness prints it (c_cases.dump: floats by their bits, text as hex). The harness
(``convert_replay.rs``) holds the cases as Rust values, runs them through ``battgen::convert`` and
writes the same lines for the test to compare."""

from __future__ import annotations

import random
import struct
from dataclasses import dataclass
from typing import Any

from c_cases import _is_char_array, dump
from rust_cases import Unrepresentable, _from_json, random_records, struct_literal

import generated.convert as converters
from codegen.apps.conversion.vectors import SIDES, VectorWriter
from codegen.backends.rust.converters import RustConverter
from codegen.backends.rust.model import type_path
from codegen.backends.rust.naming import field_ident, snake
from codegen.ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema

RANDOM = 100  # seeded random records per converter, on top of the vectors (as the C test)


@dataclass
class Case:
    cid: str
    given: list[str | None]  # Rust value per source message (None: not received)
    inputs: list[float | None]  # the converter's inputs (dt_s, ...), float32 values
    expected: str  # the line the harness must write


def _f32(value: float) -> float:
    rounded: float = struct.unpack("<f", struct.pack("<f", value))[0]
    return rounded


def _as_f32(value: Any) -> Any:
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


def _classes(qualified: list[str]) -> list[Any]:
    import importlib

    out = []
    for q in qualified:
        module = importlib.import_module("generated." + q.rsplit(".", 1)[0])
        out.append(next(c for c in vars(module).values() if getattr(c, "QUALIFIED_NAME", None) == q))
    return out


def _case(
    schema: Schema, conv: RustConverter, cid: str, plains: list[dict[str, Any] | None], inputs: list[float | None]
) -> Case:
    sources = [q for q, _, _ in conv.sources]
    objs = [None if p is None else cls.from_dict(p) for cls, p in zip(_classes(sources), plains, strict=True)]
    given = [
        None if o is None else struct_literal(schema, schema.message(q), o.to_dict())
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


def cases(schema: Schema, conv: RustConverter) -> tuple[list[Case], int]:
    """(cases, records skipped): every vector's input, then the C test's seeded random records."""
    out: list[Case] = []
    skipped = 0
    aliases = [v for _, v, _ in conv.sources]
    vectors = VectorWriter(conv.source, conv.target, conv.policy).document()["vectors"] if conv.source in SIDES else []
    endpoint = next(e for s in schema.mappings for e in s.endpoints if e.name == conv.source)
    for vector in vectors:  # type: ignore[attr-defined]
        data = _from_json(vector["input"])
        plains = [data] if len(aliases) == 1 else [data.get(a) for a in endpoint.aliases]  # type: ignore[union-attr]
        try:
            out.append(_case(schema, conv, f"vector/{vector['id']}", plains, [None] * len(conv.inputs)))
        except (Unrepresentable, ValueError, TypeError):
            skipped += 1
    rng = random.Random("battgen_convert_" + conv.name)  # the C converter's name: the C test's records
    streams = [random_records(schema, schema.message(q)) for q, _, _ in conv.sources]
    pools = [[_as_f32(p) for _, p in s] for s in streams]
    for i in range(RANDOM):
        plains = [pool[i % len(pool)] if k == 0 or rng.random() < 0.7 else None for k, pool in enumerate(pools)]
        inputs = [
            None if rng.random() < 0.3 else _f32(rng.choice([0.0, 0.1, 1.0, 2.5, -1.0, 1e3])) for _ in conv.inputs
        ]
        try:
            out.append(_case(schema, conv, f"random/{i}", plains, inputs))
        except (Unrepresentable, ValueError, TypeError, OverflowError):
            skipped += 1
    return out, skipped


# --- the harness -----------------------------------------------------------------------------------


def _path(qualified: str) -> str:
    return type_path(qualified).replace("crate::", "battgen::", 1)


def _nested(schema: Schema, msg: Message, out: list[Message]) -> None:
    if msg in out:
        return
    out.append(msg)
    for f in msg.fields:
        t = f.type
        while isinstance(t, ArrayType):
            t = t.element
        if isinstance(t, CompositeType):
            _nested(schema, schema.message(t.name), out)


def _show(t: FieldType, v: str) -> str:
    """A statement appending value ``v`` of type ``t`` to ``o`` as c_cases.dump prints it."""
    if isinstance(t, CompositeType):
        return f"o.push('{{'); dump_{snake(t.name)}(&{v}, o); o.push('}}');"
    assert isinstance(t, PrimitiveType)
    if t.kind is PrimitiveKind.FLOAT:
        return f"o.push_str(&{'f64s' if t.bits > 32 else 'f32s'}({v}));"
    if t.kind is PrimitiveKind.BOOL:
        return f'o.push_str(if {v} {{ "1" }} else {{ "0" }});'
    return f'o.push_str(&format!("{{}}", {v}));'


def _dump_fn(schema: Schema, msg: Message) -> list[str]:
    q = msg.qualified_name
    lines = [f"fn dump_{snake(q)}(m: &{_path(q)}, o: &mut String) {{"]
    for f in msg.fields:
        if f.is_padding:
            continue
        name = f"m.{field_ident(f.name)}"
        lines.append(f'o.push_str("{f.name}=");')
        t = f.type
        if _is_char_array(t):
            lines.append(f"text(&{name}, o);")
        elif isinstance(t, ArrayType):
            items = f"{name}[..{name}_len]" if t.dynamic else f"{name}"
            lines += [
                "o.push('[');",
                f"for (i, x) in {items}.iter().enumerate() {{",
                "if i > 0 { o.push(','); }",
                _show(t.element, "*x"),
                "}",
                "o.push(']');",
            ]
        else:
            lines.append(_show(t, name))
        lines.append("o.push(';');")
    return [*lines, "}"]


HEAD = """// The converter replay of battgen's Rust crate, written by tests/rust_convert_cases.py: each case's
// targets and losses, one line, as the Python package's converter gives them.
#![allow(clippy::all, unused_variables, non_snake_case)]

use battgen::convert::LossReport;

fn f32s(x: f32) -> String {
    if x.is_nan() { "nan".into() } else { format!("{:08x}", x.to_bits()) }
}

fn f64s(x: f64) -> String {
    if x.is_nan() { "nan".into() } else { format!("{:016x}", x.to_bits()) }
}

fn text(b: &[u8], o: &mut String) {
    for x in b.iter().take_while(|x| **x != 0) {
        o.push_str(&format!("{:02x}", x));
    }
}

fn losses(r: &LossReport, o: &mut String) {
    for (i, e) in r.entries().iter().enumerate() {
        if i > 0 { o.push(','); }
        o.push_str(e.kind.name());
        o.push(' ');
        o.push_str(e.field);
    }
    if r.missed() > 0 { o.push_str(&format!(" missed {}", r.missed())); }
}
"""


def _input(v: float | None) -> str:
    if v is None:
        return "None"
    return f"Some(f32::from_bits({struct.unpack('<I', struct.pack('<f', v))[0]:#010x}))"


def render(schema: Schema, convs: list[tuple[RustConverter, list[Case]]]) -> str:
    out = [HEAD]
    dumped: list[Message] = []
    for conv, _ in convs:
        for q, _v in conv.targets:
            _nested(schema, schema.message(q), dumped)
    for msg in dumped:
        out += _dump_fn(schema, msg)
    runs = []
    for conv, found in convs:
        n = conv.name
        types = [(f"Option<{_path(q)}>" if opt else _path(q)) for q, _, opt in conv.sources]
        types += ["Option<f32>"] * len(conv.inputs)
        row = "(" + ", ".join(types) + ",)"
        out.append(f"static CASES_{n.upper()}: [{row}; {len(found)}] = [")
        for c in found:
            values = [
                ("None" if g is None else f"Some({g})") if opt else str(g)
                for g, (_, _, opt) in zip(c.given, conv.sources, strict=True)
            ]
            values += [_input(v) for v in c.inputs]
            out.append("(" + ", ".join(values) + ",),")
        out.append("];")
        args = [f"c.{k}.as_ref()" if opt else f"&c.{k}" for k, (_, _, opt) in enumerate(conv.sources)]
        args += [f"c.{len(conv.sources) + k}" for k in range(len(conv.inputs))]
        outs = [f"t{k}" for k in range(len(conv.targets))]
        bind = outs[0] if len(outs) == 1 else "(" + ", ".join(outs) + ")"
        dumps = [f'dump_{snake(q)}(&t{k}, o); o.push_str(" | ");' for k, (q, _) in enumerate(conv.targets)]
        out += [
            f"fn run_{n}(o: &mut String) {{",
            f"for (j, c) in CASES_{n.upper()}.iter().enumerate() {{",
            "let mut rep = LossReport::new();",
            f"let {bind} = battgen::convert::{n}({', '.join(args)}, &mut rep);",
            f'o.push_str(&format!("{n}#{{}} ", j));',
            *dumps,
            "losses(&rep, o);",
            "o.push('\\n');",
            "}",
            "}",
        ]
        runs.append(f"run_{n}(&mut o);")
    out += [
        "#[test]",
        "fn converters_give_pythons_targets_and_losses() {",
        "let mut o = String::new();",
        *runs,
        'std::fs::write(std::env::var("BATTGEN_CONVERT_OUT").unwrap(), o).unwrap();',
        "}",
        "",
    ]
    return "\n".join(out)
