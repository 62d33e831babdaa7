"""The generated Rust crate: the committed generated/rust/ is what the backend renders, it is
`no_std`, forbids unsafe code and has no dependencies. In a temporary copy (cargo's target folder in
the temp dir too) `cargo test --offline` replays every conformance vector record and 40 seeded random
records per message (tests/rust_cases.py writes them at test time, from the generated Python package)
and must give the same bytes (MAVLink 2 payloads, v2, v1 and signed frames; uORB structs; DroneCAN
payloads with and without the tail array optimisation), decoded values and validator problems; a
wrong byte fails it, and the crate's doc examples run (the README's: decode a BATTERY_STATUS, feed
the failsafe, act on its event). `cargo fmt --check`, `cargo clippy -- -D warnings` and `cargo doc`
with warnings denied pass, upstream's whole MAVLink, DroneCAN and PX4 definitions make a clippy-clean
crate too, and a `no_std` library with its own panic handler builds against the crate (std linked in
would clash with that handler). The copy is the session's (tests/rust_crate.py), shared with the
failsafe replay (test_rust_failsafe.py): one build."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from rust_cases import Replay, render_replay, replay_test_name
from rust_crate import GENERATED, Crate, cargo, shared_crate
from shared_data import UPSTREAM, require

from codegen.apps.schemas.package import bundled_schemas
from codegen.backends.rust import render_crate
from codegen.backends.rust.render import rust_messages
from codegen.backends.rust.rules import rust_rules
from codegen.frontends.loader import load
from codegen.ir.rules import bound_rules

needs_rustfmt = pytest.mark.skipif(shutil.which("rustfmt") is None, reason="rustfmt not installed")
needs_cargo = pytest.mark.skipif(shutil.which("cargo") is None, reason="cargo not installed")


@needs_rustfmt
def test_committed_crate_is_fresh() -> None:
    files = render_crate(load([bundled_schemas()]))
    assert "src/mavlink/battery_status.rs" in files
    for rel, text in files.items():
        assert (GENERATED / rel).read_text(encoding="utf-8") == text, rel


def test_every_cross_field_rule_of_the_crates_messages_is_in_it() -> None:
    schema = load([bundled_schemas()])
    methods = []
    for msg in rust_messages(schema):
        found = rust_rules(schema, msg)
        assert found.left == [], found.left  # none left out: the replay compares them all with Python's
        methods += found.calls
    assert len(methods) >= 6, methods  # BatteryInfo 2, PrimaryPowerSupplyStatus 1, BATTERY_STATUS 1, uORB 2+2


def test_crate_is_no_std_without_unsafe_or_dependencies() -> None:
    lib = (GENERATED / "src" / "lib.rs").read_text(encoding="utf-8")
    assert "#![no_std]\n" in lib
    assert "#![forbid(unsafe_code)]\n" in lib
    for path in (GENERATED / "src").rglob("*.rs"):
        text = path.read_text(encoding="utf-8")
        assert re.search(r"\bstd::|extern crate", text) is None, path
    manifest = (GENERATED / "Cargo.toml").read_text(encoding="utf-8")
    assert manifest.rstrip().endswith("[dependencies]"), "the crate must have no dependencies"


@needs_rustfmt
def test_cli_writes_and_checks_a_rust_crate(tmp_path: Path) -> None:
    from codegen.cli.main import main

    out = tmp_path / "crate"
    assert main(["generate", "--lang", "rust", "-o", str(out)]) == 0
    assert (out / "src" / "lib.rs").is_file()
    assert main(["generate", "--lang", "rust", "-o", str(out), "--check"]) == 0
    (out / "src" / "lib.rs").write_text("// edited\n")
    assert main(["generate", "--lang", "rust", "-o", str(out), "--check"]) == 1
    (out / "src" / "stray.rs").write_text("// not generated\n")
    assert main(["generate", "--lang", "rust", "-o", str(out)]) == 0
    assert not (out / "src" / "stray.rs").exists()


@pytest.fixture(scope="module")
def crate(tmp_path_factory: pytest.TempPathFactory) -> Crate:
    """The session's copy of generated/rust with the replay cases written into its tests/ folder."""
    return shared_crate(tmp_path_factory)


@needs_cargo
def test_cargo_test_replays_every_vector_record(crate: Crate) -> None:
    counts = {r.qualified: len(r.cases) for r in crate.replays}
    # the codecs' messages are all reached, each with many distinct records
    for qualified in ("mavlink.BATTERY_STATUS", "mavlink.BATTERY_STATUS_V2", "uorb.BatteryStatus"):
        assert counts.get(qualified, 0) >= 50, counts
    assert any('range"' in c for r in crate.replays for c in r.cases), "no case breaks a range"
    # the cross-field rules are compared too: every rule of every message is broken by some case
    broken = {
        (r.qualified, rule) for r in crate.replays for c in r.cases for rule in re.findall(r"cross-field:([\w-]+)", c)
    }
    schema = load([bundled_schemas()])
    rules = {(m.qualified_name, b.rule.id) for m in rust_messages(schema) for b in bound_rules(schema, m)}
    assert len(rules) >= 8 and rules <= broken, rules - broken
    done = cargo(crate, "test", "--offline")
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    for r in crate.replays:
        assert f"test {replay_test_name(r)} ... ok" in done.stdout, replay_test_name(r)
    assert re.search(r"test src/lib\.rs - \(line \d+\) \.\.\. ok", done.stdout), "the crate's doc example did not run"
    # the README's example: decode a BATTERY_STATUS, feed the failsafe, act on its event
    assert re.search(r"test src/lib\.rs - ReadmeDoctests \(line \d+\) \.\.\. ok", done.stdout), "README example"


@needs_cargo
def test_cargo_test_fails_on_a_wrong_byte(crate: Crate, tmp_path: Path) -> None:
    """The replay compares: a uORB BatteryStatus case whose struct's first byte is off by one fails."""
    root = tmp_path / "battgen"
    shutil.copytree(crate.root, root, ignore=shutil.ignore_patterns("tests"))
    (root / "tests").mkdir()
    status = next(r for r in crate.replays if r.qualified == "uorb.BatteryStatus")
    # a case is ((id, value, problems, decoded), &[struct bytes...], problems)
    case = re.sub(r"\}\), &\[(\d+)", lambda m: "}), &[" + str((int(m.group(1)) + 1) % 256), status.cases[0], count=1)
    assert case != status.cases[0]
    broken = Replay(status.kind, status.qualified, [case])
    (root / "tests" / "replay.rs").write_text(render_replay(load([bundled_schemas()]), [broken]), encoding="utf-8")
    done = cargo(Crate(root, crate.target, [broken], []), "test", "--offline")
    assert done.returncode != 0
    assert "struct bytes" in done.stdout + done.stderr


@needs_cargo
@needs_rustfmt
def test_cargo_fmt_check(crate: Crate, tmp_path: Path) -> None:
    """The crate as committed (the replay data, not formatted, left out)."""
    root = tmp_path / "battgen"
    shutil.copytree(GENERATED, root, ignore=shutil.ignore_patterns("target", "Cargo.lock"))
    done = cargo(Crate(root, crate.target, [], []), "fmt", "--check")
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]


@needs_cargo
def test_cargo_clippy_denies_every_warning(crate: Crate) -> None:
    if cargo(crate, "clippy", "--version").returncode != 0:
        pytest.skip("clippy not installed")
    done = cargo(crate, "clippy", "--offline", "--", "-D", "warnings")
    assert done.returncode == 0, done.stderr[-4000:]


@needs_cargo
def test_cargo_doc_without_warnings(crate: Crate) -> None:
    """The schema's words reach rustdoc as words: no broken links, HTML or bare URLs."""
    done = cargo(crate, "doc", "--offline", "--no-deps", env={"RUSTDOCFLAGS": "-D warnings"})
    assert done.returncode == 0, done.stderr[-4000:]


@needs_cargo
@needs_rustfmt
def test_upstream_definitions_make_a_clippy_clean_crate(crate: Crate, tmp_path: Path) -> None:
    """Beyond the bundled schemas: every MAVLink dialect upstream publishes (all.xml), the whole DSDL
    tree pydronecan ships and PX4 main's msg/ render into one crate that builds clippy-clean (names
    that clash with the prelude or the struct, enum members that spell alike, NaN markers, empty
    messages, namespaces that repeat their parent's name)."""
    dronecan = pytest.importorskip("dronecan")
    paths = [
        require(UPSTREAM / "mavlink" / "all.xml"),
        Path(dronecan.__file__).parent / "dsdl_specs",
        require(UPSTREAM / "px4_msgs" / "main"),
    ]
    files = render_crate(load(paths))
    assert len([rel for rel in files if rel.endswith(".rs")]) > 500
    root = tmp_path / "battgen"
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")
    done = cargo(
        Crate(root, crate.target.parent / "target-upstream", [], []), "clippy", "--offline", "--", "-D", "warnings"
    )
    if "no such command" in done.stderr:
        pytest.skip("clippy not installed")
    assert done.returncode == 0, done.stderr[-4000:]


NO_STD_LIB = """#![no_std]
//! A firmware-like user of the crate: no std, its own panic handler.

use battgen::mavlink::BatteryStatus;
use battgen::mavlink_wire::decode_frame;

/// The remaining charge of a BATTERY_STATUS frame, None when unknown or not a valid frame.
pub fn remaining(frame: &[u8]) -> Option<i8> {
    let (_, msg) = decode_frame::<BatteryStatus>(frame).ok()?;
    if msg.validate().is_empty() {
        msg.battery_remaining()
    } else {
        None
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
"""


@needs_cargo
def test_a_no_std_library_builds_against_the_crate(crate: Crate) -> None:
    user = crate.root.parent / "nostd_user"
    (user / "src").mkdir(parents=True)
    (user / "Cargo.toml").write_text(
        '[package]\nname = "nostd_user"\nversion = "0.0.0"\nedition = "2021"\n\n'
        '[lib]\ncrate-type = ["staticlib"]\n\n[dependencies]\nbattgen = { path = "../battgen" }\n\n'
        '[profile.dev]\npanic = "abort"\n',
        encoding="utf-8",
    )
    (user / "src" / "lib.rs").write_text(NO_STD_LIB, encoding="utf-8")
    alone = Crate(user, crate.target.parent / "target-nostd", [], [])
    done = cargo(alone, "build", "--offline")
    assert done.returncode == 0, done.stderr[-4000:]
    assert (alone.target / "debug" / "libnostd_user.a").is_file()
