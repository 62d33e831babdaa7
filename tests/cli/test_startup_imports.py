"""What a command imports at start-up (the list, not the time: benchmarks/bench_startup.py times it).

`battgen --help` builds its parser from main's table of commands and imports no command module; a command
imports its own module and what it uses; reading one JSON record with the bundled schemas' IR cached
parses no schema and imports neither the code generator nor any heavy dependency."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.cli import main as cli

# never on the path of --help (or of reading a record, below)
HEAVY = ("jsonschema", "pandas", "pyarrow", "plotly", "numpy", "pydsdl", "can", "jinja2", "yaml")

_RUN = """
import json, sys
from codegen.cli.main import main
try:
    code = main(sys.argv[1:])
except SystemExit as exit:
    code = exit.code
print(json.dumps({"code": code, "modules": sorted(sys.modules)}), file=sys.stderr)
"""


def _modules(args: list[str], cache: Path) -> tuple[int, str, set[str]]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache)}
    done = subprocess.run(
        [sys.executable, "-c", _RUN, *args], capture_output=True, text=True, cwd=ROOT, env=env, check=False, timeout=120
    )
    *printed, last = done.stderr.strip().splitlines()
    report = json.loads(last)
    return int(report["code"]), done.stdout + "\n".join(printed), set(report["modules"])


def _heavy(modules: set[str], names: tuple[str, ...]) -> list[str]:
    return sorted(m for m in modules if m.split(".")[0] in names)


def test_help_imports_no_command_and_no_dependency(tmp_path: Path) -> None:
    code, out, modules = _modules(["--help"], tmp_path)
    assert code == 0 and "validate" in out and "report" in out
    assert _heavy(modules, HEAVY) == []
    ours = sorted(m for m in modules if m.startswith("codegen."))
    assert ours == ["codegen.cli", "codegen.cli.main", "codegen.errors", "codegen.text", "codegen.text.escape"]
    assert not tmp_path.exists() or not any(tmp_path.iterdir())  # nor any schema read


def test_validate_of_one_record_parses_no_schema_once_cached(tmp_path: Path) -> None:
    record = tmp_path / "one.jsonl"
    record.write_text('{"voltage_v": 16.4, "remaining": 0.5, "max_error": 1}\n', encoding="utf-8")
    args = ["validate", "--message", "uorb.BatteryStatus", str(record)]
    cache = tmp_path / "cache"
    first = _modules(args, cache)
    assert first[0] == 0 and "1 record in 1 file, 0 errors" in first[1]
    assert any((cache / "battgen").iterdir())  # the bundled schemas' IR stored
    code, out, modules = _modules(args, cache)
    assert (code, out) == first[:2]  # the same verdict from the cached IR
    assert _heavy(modules, ("jsonschema", "pandas", "pyarrow", "plotly", "numpy", "pydsdl", "can", "jinja2")) == []
    # no schema parsed: neither the loader nor any frontend; no code generator
    assert sorted(m for m in modules if m.startswith(("codegen.frontends.", "codegen.backends.python.writer"))) == [
        "codegen.frontends.cache"
    ]
    # of the Python backend, the naming of a message's module and class alone (not the renderer's parts)
    assert sorted(m for m in modules if m.startswith("codegen.backends.python.")) == [
        "codegen.backends.python.formatting",
        "codegen.backends.python.literals",
        "codegen.backends.python.naming",
    ]
    assert not any(
        m.startswith("codegen.cli.")
        and m
        not in ("codegen.cli.main", "codegen.cli.validate", "codegen.cli.gate_options", "codegen.cli.cyphal_options")
        for m in modules
    )


def test_convert_of_json_lines_imports_no_log_reader_nor_generator(tmp_path: Path) -> None:
    record = tmp_path / "one.jsonl"
    record.write_text('{"voltage": 16.4, "temperature": 298.15}\n', encoding="utf-8")
    out = tmp_path / "out.jsonl"
    args = ["convert", "--from", "dronecan", "--to", "mavlink", "--policy", "px4", str(record), "-o", str(out)]
    code, _, modules = _modules(args, tmp_path / "cache")
    assert code == 0 and len(out.read_text(encoding="utf-8").splitlines()) == 1
    # python-can, the log and devicetree readers and the code generator belong to other inputs and commands
    assert _heavy(modules, ("jsonschema", "pandas", "pyarrow", "plotly", "numpy", "pydsdl", "can", "jinja2")) == []
    readers = ("codegen.inputs.can", "codegen.inputs.devicetree", "codegen.inputs.ulog.records", "codegen.inputs.tlog")
    assert sorted(m for m in modules if m.startswith(readers)) == []
    assert "codegen.backends.python.registry" not in modules


@pytest.mark.parametrize("command", [None, *(name for name, _ in cli.COMMANDS), "list", "generate"])
def test_the_lazy_parser_prints_what_the_full_one_does(command: str | None, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["--help"] if command is None else [command, "--help"]
    printed = []
    for parser in (cli.build_parser(), cli.build_parser(argv)):
        with pytest.raises(SystemExit):
            parser.parse_args(argv)
        printed.append(capsys.readouterr().out)
    assert printed[0] == printed[1] and "usage: battgen" in printed[0]
