"""One copy of the generated Rust crate a test session, with its replay data written into its tests/
folder (the vector replay of tests/rust_cases.py, the failsafe replay of tests/rust_failsafe_cases.py, the
parameter tables' printout of backends/rust_params_table.rs), and
cargo run in it with its build output in the session's temp dir: the Rust test modules share one build."""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
import rust_failsafe_cases
from rust_cases import Replay, collect, generated_classes, render_replay

from codegen.apps.schemas.package import bundled_schemas, project_root
from codegen.frontends.loader import load

GENERATED = project_root() / "generated" / "rust"
PARAMS_HARNESS = Path(__file__).parent / "backends" / "rust_params_table.rs"


@dataclass(frozen=True)
class Crate:
    root: Path
    target: Path
    replays: list[Replay]
    streams: list[rust_failsafe_cases.Stream]


def cargo(crate: Crate, *args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """cargo in the crate's folder, its build output in the temp dir, never the network."""
    full = {**os.environ, "CARGO_TARGET_DIR": str(crate.target), "CARGO_NET_OFFLINE": "true", **(env or {})}
    return subprocess.run(
        ["cargo", *args], cwd=crate.root, env=full, capture_output=True, text=True, check=False, timeout=600
    )


_CRATES: dict[Path, Crate] = {}


def shared_crate(tmp_path_factory: pytest.TempPathFactory) -> Crate:
    """The session's copy of generated/rust with both replays in its tests/ folder (made once)."""
    if shutil.which("cargo") is None:
        pytest.skip("cargo not installed")
    base = tmp_path_factory.getbasetemp()
    if base not in _CRATES:
        work = base / "rust"
        root = work / "battgen"
        shutil.rmtree(work, ignore_errors=True)
        shutil.copytree(GENERATED, root, ignore=shutil.ignore_patterns("target", "Cargo.lock"))
        schema = load([bundled_schemas()])
        replays = collect(schema, generated_classes(schema))
        (root / "tests").mkdir()
        (root / "tests" / "replay.rs").write_text(render_replay(schema, replays), encoding="utf-8")
        streams = rust_failsafe_cases.collect()
        rust_failsafe_cases.write(streams, root / "tests" / "failsafe_streams.txt")
        shutil.copyfile(rust_failsafe_cases.HARNESS, root / "tests" / "failsafe_replay.rs")
        shutil.copyfile(PARAMS_HARNESS, root / "tests" / "params_table.rs")
        _CRATES[base] = Crate(root, work / "target", replays, streams)
    return _CRATES[base]
