"""DroneCAN unions in the Rust crate: the C library's union test's small DSDL definitions (a union of
an empty type, a number, an array and a float16; a union as the last field of a structure, where the tail array
optimisation reaches the held array; a three-field union, whose fourth tag names nothing) rendered as a
crate and run by cargo: every branch's bytes equal pydronecan's for the same definitions, with and
without the tail array optimisation; the bytes read back give the same branch and re-encode to the same
bytes; a tag naming no field is refused both ways; the validator checks the held field only."""

from __future__ import annotations

import importlib
import os
import shutil
import subprocess
import sys
from typing import Any

import pytest

# the same definitions as the C library's union test, and pydronecan's bytes for them
from test_c_dronecan_unions_c import DEFINITIONS, _reference

from codegen.backends.python.writer import generate
from codegen.backends.rust.render import render_crate
from codegen.frontends import dsdl

# (type, Rust struct fields, the values pydronecan is given: the branch and its value)
CASES: list[tuple[str, str, dict[str, Any]]] = [
    ("Pick", "union_tag: 0", {"none": None}),
    ("Pick", "union_tag: 1, number: -1234", {"number": -1234}),
    ("Pick", "union_tag: 1, number: 32767", {"number": 32767}),
    ("Pick", "union_tag: 2, raw_len: 0", {"raw": []}),
    ("Pick", "union_tag: 2, raw_len: 3, raw: [1, 2, 255, 0]", {"raw": [1, 2, 255]}),
    ("Pick", "union_tag: 2, raw_len: 4, raw: [9, 8, 7, 6]", {"raw": [9, 8, 7, 6]}),
    ("Pick", "union_tag: 3, half: 1.5", {"half": 1.5}),
    ("Pick", "union_tag: 3, half: 70000.0", {"half": 70000.0}),
    ("Pick", "union_tag: 3, half: -0.0", {"half": -0.0}),
    (
        "Holder",
        "index: 7, pick: Pick { union_tag: 2, raw_len: 2, raw: [5, 6, 0, 0], ..Pick::new() }",
        {"index": 7, "raw": [5, 6]},
    ),
    ("Holder", "index: 1, pick: Pick { union_tag: 1, number: -2, ..Pick::new() }", {"index": 1, "number": -2}),
    ("Holder", "index: 0, pick: Pick::new()", {"index": 0, "none": None}),
    ("Three", "union_tag: 0, a: 200", {"a": 200}),
    ("Three", "union_tag: 1, b: 65535", {"b": 65535}),
    ("Three", "union_tag: 2, c: 3.25", {"c": 3.25}),
]

MAIN = """use battgen::dronecan::test::{Holder, Pick, Three};
use battgen::dronecan_wire::{DecodeError, EncodeError, Message};

fn hex(data: &[u8]) -> String {
    data.iter().map(|b| format!("{b:02x}")).collect()
}

/// Both encodings, then the branch read back from the first and whether it re-encodes the same.
fn case<M: Message>(given: &M, tag: impl Fn(&M) -> u8) {
    let mut buf = [0u8; 64];
    let mut again = [0u8; 64];
    let n = given.encode(&mut buf, true).unwrap();
    let tao = hex(&buf[..n]);
    let k = given.encode(&mut buf, false).unwrap();
    let fd = hex(&buf[..k]);
    given.encode(&mut buf, true).unwrap(); // the first encoding again, to read back
    let back = M::decode(&buf[..n], true).unwrap();
    let m = back.encode(&mut again, true).unwrap();
    println!("{tao} {fd} {} {}", tag(&back), again[..m] == buf[..n]);
}

fn main() {
CASES
    let three = Three::decode(&[0xC0, 0, 0, 0, 0], true).err();
    assert_eq!(three, Some(DecodeError::Tag { tag: 3, fields: 3 }));
    let wrong = Three { union_tag: 3, ..Three::new() };
    let mut buf = [0u8; 8];
    assert_eq!(wrong.encode(&mut buf, true).err(), Some(EncodeError::Tag { tag: 3, fields: 3 }));
    println!("refused");
    // a union's validator checks the field it holds only: the others are not sent
    let mut p = Pick { union_tag: 1, half: f32::NAN, ..Pick::new() };
    let held = p.validate();
    p.union_tag = 3;
    let found = p.validate();
    println!("{} {} {}", held.len(), found.len(), found.as_slice()[0].field);
    // a tag naming no field: the validator's union problem, as Python's (printed `path rule;...`)
    let named = |v: &[battgen::Problem]| -> String {
        v.iter().map(|p| format!("{} {};", p.field, p.rule.name())).collect()
    };
    println!("{}", named(Three { union_tag: 3, ..Three::new() }.validate().as_slice()));
    println!("{}", named(Three { union_tag: 255, ..Three::new() }.validate().as_slice()));
    let pick = Pick { union_tag: 4, number: 2, ..Pick::new() };
    println!("{}", named(Holder { index: 1, pick }.validate().as_slice()));
}
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[str], dict[str, Any]]:
    pydronecan = pytest.importorskip("dronecan")
    if shutil.which("cargo") is None:
        pytest.skip("cargo not installed")
    base = tmp_path_factory.mktemp("rust_union")
    folder = base / "dsdl" / "test"
    folder.mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (folder / name).write_text(text)
    crate = base / "crate"
    for rel, text in render_crate(dsdl.parse_dir(base / "dsdl")).items():
        (crate / rel).parent.mkdir(parents=True, exist_ok=True)
        (crate / rel).write_text(text, encoding="utf-8")
    calls = []
    for name, given, _ in CASES:
        tag = "|m| m.pick.union_tag" if name == "Holder" else "|m| m.union_tag"
        calls.append(f"    case(&{name} {{ {given}, ..{name}::new() }}, {tag});")
    (crate / "examples").mkdir()
    (crate / "examples" / "unions.rs").write_text(MAIN.replace("CASES\n", "\n".join(calls) + "\n"), encoding="utf-8")
    env = {**os.environ, "CARGO_TARGET_DIR": str(base / "target"), "CARGO_NET_OFFLINE": "true"}
    done = subprocess.run(
        ["cargo", "run", "--offline", "-q", "--example", "unions"],
        cwd=crate,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    types = {t.full_name: t for t in pydronecan.dsdl.parse_namespaces([str(folder)])}
    return done.stdout.splitlines(), types


def test_every_branch_is_pydronecans_bytes(run: tuple[list[str], dict[str, Any]]) -> None:
    out, types = run
    assert len(out) == len(CASES) + 5
    for line, (name, given, values) in zip(out, CASES, strict=False):
        tao, fd, _, _ = line.split(" ")
        assert tao == _reference(types, name, values, True), (name, given)
        assert fd == _reference(types, name, values, False), (name, given)


def test_bytes_read_back_hold_the_same_branch(run: tuple[list[str], dict[str, Any]]) -> None:
    out, _ = run
    for line, (name, given, _) in zip(out, CASES, strict=False):
        _, _, tag, same = line.split(" ")
        expected = given.split("union_tag: ")[1].split(",")[0].split(" ")[0] if "union_tag" in given else "0"
        assert (tag, same) == (expected, "true"), (name, given)


def test_a_tag_naming_no_field_is_refused(run: tuple[list[str], dict[str, Any]]) -> None:
    out, _ = run
    assert out[-5] == "refused"  # the example asserts both errors before printing this


def test_a_union_validates_the_field_it_holds(run: tuple[list[str], dict[str, Any]]) -> None:
    out, _ = run
    assert out[-4] == "0 1 half"  # NaN in half: no problem while number is held, one once half is


def test_a_tag_naming_no_field_is_pythons_union_problem(
    run: tuple[list[str], dict[str, Any]], tmp_path_factory: pytest.TempPathFactory
) -> None:
    """The generated Python package of the same definitions, its union_field set to no field (what a
    Rust tag beyond the fields is), reports the same problems (path and rule) as the Rust validator."""
    base = tmp_path_factory.mktemp("py_union")
    (base / "dsdl" / "test").mkdir(parents=True)
    for name, text in DEFINITIONS.items():
        (base / "dsdl" / "test" / name).write_text(text)
    generate(dsdl.parse_dir(base / "dsdl"), base / "out" / "rs_union")
    sys.path.insert(0, str(base / "out"))
    try:
        mod = importlib.import_module("rs_union.dronecan.test")
        three = mod.Three(a=0)
        object.__setattr__(three, "union_field", None)  # no field of the union, as tags 3 and 255
        pick = mod.Pick(number=2)
        object.__setattr__(pick, "union_field", None)
        holder = mod.Holder(index=1, pick=pick)
        expected = ["".join(f"{v.path} {v.rule};" for v in obj.validate()) for obj in (three, three, holder)]
    finally:
        sys.path.remove(str(base / "out"))
        for name in [n for n in sys.modules if n.split(".")[0] == "rs_union"]:
            del sys.modules[name]
    out, _ = run
    assert expected == ["union_field union;", "union_field union;", "pick.union_field union;"]
    assert out[-3:] == expected
