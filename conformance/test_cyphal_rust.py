"""The Rust crate's Cyphal codecs (generated/rust/src/cyphal/) against pydsdl and the generated Python package.

The cases of ``cyphal_native_cases`` (those of the C library's test: hypothesis-drawn values and values beyond
each cast's range; bytes truncated, extended, behind right, extended and too-long delimiter headers, random)
are written as an example program of a copy of the crate and run by cargo: each value's serialization, with
and without the delimiter header, must be pydsdl's bytes; each byte string must read as pydsdl reads it (or
be refused where pydsdl refuses it), and what was read must serialize as pydsdl serializes it."""

from __future__ import annotations

import math
import os
import re
import shutil
import struct
import subprocess
from pathlib import Path
from typing import Any

import pytest
from cyphal_native_cases import TypeCases, all_cases, definition_cases, dump, has_nan
from test_cyphal_c import compare

from codegen.apps.schemas.package import project_root
from codegen.backends.rust.cyphal_codec import rust_path
from codegen.backends.rust.naming import field_ident
from codegen.backends.rust.render import render_crate
from codegen.backends.rust.types import scalar, scalar_literal
from codegen.ir import ArrayType, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType, Schema

CRATE = project_root() / "generated" / "rust"

HELPERS = """use battgen::cyphal_wire::{EncodeError, Message};

fn hex(data: &[u8]) -> String {
    data.iter().map(|b| format!("{b:02x}")).collect()
}

trait Dump {
    fn dump(&self, o: &mut String);
}

fn pf(o: &mut String, v: f32) {
    o.push_str(&if v.is_nan() { "nan".to_string() } else { format!("{:08x}", v.to_bits()) });
}

fn pd(o: &mut String, v: f64) {
    o.push_str(&if v.is_nan() { "nan".to_string() } else { format!("{:016x}", v.to_bits()) });
}

fn enc<M: Message>(key: &str, m: &M) {
    let mut buf = [0u8; 1024];
    let plain = match m.encode(&mut buf, false) {
        Ok(n) => hex(&buf[..n]),
        Err(_) => "error".to_string(),
    };
    println!("enc {key} {plain}");
    let headed = match m.encode(&mut buf, true) {
        Ok(n) => hex(&buf[..n]),
        Err(EncodeError::Sealed) => "sealed".to_string(),
        Err(_) => "error".to_string(),
    };
    println!("hdr {key} {headed}");
}

fn dec<M: Message + Dump>(key: &str, data: &[u8], header: bool) {
    let mut buf = [0u8; 1024];
    match M::decode(data, header) {
        Err(_) => println!("dec {key} error"),
        Ok(m) => {
            let mut o = String::new();
            m.dump(&mut o);
            let again = match m.encode(&mut buf, false) {
                Ok(n) => hex(&buf[..n]),
                Err(_) => "error".to_string(),
            };
            println!("dec {key} {o} {again}");
        }
    }
}
"""


class Unrepresentable(ValueError):
    """A value a Rust literal does not spell (a NaN other than f32::NAN's bits)."""


def _literal(t: PrimitiveType, v: Any) -> str:
    if t.kind is PrimitiveKind.FLOAT and math.isnan(v):
        bits = struct.unpack("<I", struct.pack("<f", v))[0] if t.bits <= 32 else None
        if t.bits > 32 or bits != 0x7FC00000:
            raise Unrepresentable(v)
    if scalar(t) == "f32" and abs(v) == 3.4028234663852886e38:
        return "f32::MAX" if v > 0 else "f32::MIN"  # types.f32_literal's decimal search overflows at the bound
    return scalar_literal(t, v)


def _assigns(schema: Schema, t: FieldType, v: Any, target: str) -> list[str]:
    if isinstance(t, PrimitiveType):
        return [f"{target} = {_literal(t, v)};"]
    if isinstance(t, CompositeType):
        msg = schema.message(t.name)
        fields = [(k, f) for k, f in enumerate(msg.fields) if not f.is_padding and f.name in v]
        out = [f"{target}.union_tag = {fields[0][0]};"] if msg.is_union else []
        for _, f in fields:
            out += _assigns(schema, f.type, v[f.name], f"{target}.{field_ident(f.name)}")
        return out
    assert isinstance(t, ArrayType), t
    out = [line for i, e in enumerate(v) for line in _assigns(schema, t.element, e, f"{target}[{i}]")]
    return [*out, f"{target}_len = {len(v)};"] if t.dynamic else out


def _print(t: FieldType, v: str) -> list[str]:
    if isinstance(t, CompositeType):
        return ["o.push('{');", f"{v}.dump(o);", "o.push('}');"]
    assert isinstance(t, PrimitiveType), t
    if t.kind is PrimitiveKind.FLOAT:
        return [f"pd(o, {v});" if scalar(t) == "f64" else f"pf(o, {v});"]
    if t.kind is PrimitiveKind.BOOL:
        return [f'o.push_str(if {v} {{ "1" }} else {{ "0" }});']
    return [f"o.push_str(&{v}.to_string());"]


def _dump_rust(schema: Schema, msg: Message) -> list[str]:
    """The example's ``Dump`` of a type: every field as ``c_cases.dump`` prints it."""
    lines = [f"impl Dump for {rust_path(schema, msg.qualified_name).replace('crate::', 'battgen::')} {{"]
    lines.append("fn dump(&self, o: &mut String) {")
    fields = [f for f in msg.fields if not f.is_padding]
    if msg.is_union:
        lines += ['o.push_str(&format!("tag={};", self.union_tag));', "match self.union_tag {"]
    for k, f in enumerate(fields):
        if msg.is_union:
            lines.append(f"{k} => {{")
        ident = f"self.{field_ident(f.name)}"
        lines.append(f'o.push_str("{f.name}=");')
        t = f.type
        if isinstance(t, ArrayType):
            used = f"{ident}[..{ident}_len]" if t.dynamic else ident
            lines += ["o.push('[');", f"for (i, e) in {used}.iter().enumerate() {{", "if i > 0 { o.push(','); }"]
            lines += [*_print(t.element, "e" if isinstance(t.element, CompositeType) else "*e"), "}", "o.push(']');"]
        else:
            lines += _print(t, ident)
        lines.append("o.push(';');")
        if msg.is_union:
            lines.append("}")
    if msg.is_union:
        lines += ["_ => {}", "}"]
    if not fields:
        lines.append("let _ = o;")
    return [*lines, "}", "}"]


def _program(schema: Schema, cases: list[TypeCases]) -> tuple[str, list[str]]:
    expected: list[str] = []
    body: list[str] = []
    impls: list[str] = []
    for msg in schema.messages:
        if msg.cyphal is not None:
            impls += _dump_rust(schema, msg)
    for c in cases:
        path = rust_path(schema, c.name).replace("crate::", "battgen::")
        given = 0
        for v in c.values:
            try:
                lines = _assigns(schema, CompositeType(c.name), v.given, "m")
            except Unrepresentable:
                assert has_nan(v.given), v.given
                continue
            mutable = "mut " if lines else ""
            body += ["{", f"let {mutable}m = {path}::new();", *lines, f'enc("{c.name}#{given}", &m);', "}"]
            expected.append(f"enc {c.name}#{given} {v.wire.hex()}")
            expected.append(f"hdr {c.name}#{given} {v.headed.hex() if v.headed is not None else 'sealed'}")
            given += 1
        for k, r in enumerate(c.reads):
            data = ", ".join(str(b) for b in r.data)
            body.append(f'dec::<{path}>("{c.name}#{k}", &[{data}], {"true" if r.header else "false"});')
            if r.decoded is None:
                expected.append(f"dec {c.name}#{k} error")
            else:
                again = r.again.hex() if r.again is not None else "-"
                expected.append(f"dec {c.name}#{k} {dump(schema, c.msg, r.decoded)} {again}")
    program = [HELPERS, *impls, "", "fn main() {", *body, "}", ""]
    return "\n".join(program), expected


def _cargo_run(tmp_path: Path, files: dict[str, str] | None, text: str) -> list[str]:
    """The program run as an example of the crate (generated/rust, or ``files`` rendered for other types)."""
    if shutil.which("cargo") is None:
        if os.environ.get("CI"):
            pytest.fail("cargo not installed (CI installs it)")
        pytest.skip("cargo not installed")
    crate = tmp_path / "crate"
    if files is None:
        shutil.copytree(CRATE, crate, ignore=shutil.ignore_patterns("target", "Cargo.lock"))
    for rel, body in (files or {}).items():
        (crate / rel).parent.mkdir(parents=True, exist_ok=True)
        (crate / rel).write_text(body, encoding="utf-8")
    (crate / "examples").mkdir()
    (crate / "examples" / "cyphal.rs").write_text(text, encoding="utf-8")
    env = {**os.environ, "CARGO_TARGET_DIR": str(tmp_path / "target"), "CARGO_NET_OFFLINE": "true"}
    done = subprocess.run(
        ["cargo", "run", "--offline", "-q", "--example", "cyphal"],
        cwd=crate,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout.splitlines()


def test_rust_cyphal_codecs_are_pydsdls(tmp_path: Path) -> None:
    schema, cases = all_cases()
    text, expected = _program(schema, cases)
    got = _cargo_run(tmp_path, None, text)
    compare(expected, got, cases)
    assert len(cases) == 19
    assert {line.split(" ")[0] for line in got} == {"enc", "hdr", "dec"}
    assert sum(1 for line in got if line.endswith(" error")) >= 19


def test_rust_cyphal_unions_and_nested_delimited_types_are_pydsdls(tmp_path: Path) -> None:
    """What the bundled types lack (cyphal_native_cases.DEFINITIONS): a union's tag and held field, a
    delimited type nested alone and in an array behind its delimiter header; the crate rendered for them."""
    schema, cases = definition_cases(tmp_path / "dsdl")
    text, expected = _program(schema, cases)
    got = _cargo_run(tmp_path, render_crate(schema), text)
    compare(expected, got, cases)
    assert any(re.search(r"pick=\{tag=2;inner=\{a=\d+;b=\[[0-9a-f,]+\];\};\}", line) for line in got)
