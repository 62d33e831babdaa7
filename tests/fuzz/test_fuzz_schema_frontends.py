"""Schema-side fuzzers: every frontend, fed mutants of the bundled schemas and random text.

The property (issue 10): a schema either loads or is refused with a BattgenError (a clear
``file:line: expected ...``); nothing else escapes, nothing hangs (a per-input alarm), and a schema
that loads also generates, every module written compiling. Rendering and compiling cost more than
parsing, so one accepted mutant in ``COMPILE_EVERY`` (all of them in the long mode; a third of that for
mappings and rules, which render the whole package) goes that far.

Budget: tests/fuzz/budget.py (short in CI, ``BATTGEN_FUZZ=long`` for a long run). In the long mode a
crash is saved as ``tests/fuzz/crashers/schema-<target>/<site>.<ext>`` (one file per crash site, the
shortest input kept); every saved input is replayed on every run. ``BATTGEN_FUZZ_STATS=FILE`` appends
one JSON line per target with the inputs tried and their outcomes (the closing note's figures).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import signal
import traceback
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

import pytest
from budget import CRASHERS, LONG, crashers, fuzz_settings
from conftest import ROOT
from hypothesis import example, given
from hypothesis import strategies as st

from codegen.backends.python import render_package
from codegen.errors import BattgenError
from codegen.frontends import mappings, rules
from codegen.frontends.loader import load, load_schema_dir
from codegen.ir import Schema

SCHEMAS = ROOT / "schemas"
FORMATS = ("uorb", "dronecan", "devicetree", "mavlink", "cyphal", "params")
HANG_SECONDS = 30  # per input, on a loaded 2-core machine; the slowest real schema parses in 50 ms
RENDER_SECONDS = 300  # generating the whole package takes 2 s alone, far more under load
COMPILE_EVERY = 1 if LONG else 4
# CI examples per target: the whole-package targets (mappings, rules) cost a full load and render each
CI_MUTANTS = {"mappings": 10, "rules": 15}


@dataclass(frozen=True)
class Target:
    folder: str  # the schema sub-folder holding the victim
    victim: str  # the file replaced by each input, relative to the folder
    tokens: tuple[str, ...]  # fragments of the format worth inserting


NUMBERS = ("0", "-1", "255", "256", "65536", "4294967296", "18446744073709551616", "-9223372036854775809",
           "1e999", "-1e999", "NaN", "inf", "0x7FFFFFFF", "0b101", "1.5", "9" * 300, "9999999999")  # fmt: skip
NAMES = ("ClassVar", "Any", "Mapping", "dataclasses", "struct", "math", "enum", "mro", "name", "value", "int",
         "float", "class", "None", "self", "__init__", "_", "QUALIFIED_NAME", "decode", "to_dict", "Struct",
         "ValueError", "x" * 300, "é", "a-b", "1st")  # fmt: skip
TARGETS: dict[str, Target] = {
    "uorb": Target("uorb", "BatteryStatus.msg", ("[@range 0, 1]", "[@invalid NaN]", "[@enum X]", "# TOPICS a b",
                   "uint8[4] ", "char[3] ", "float64 ", "bool ", " = ", "BatteryStatus ", "[V]", "[%]")),
    "dsdl": Target("dronecan", "uavcan/equipment/power/1092.BatteryInfo.uavcan", ("uint8[<=4] ", "void3\n",
                   "@union\n", "---\n", "saturated ", "truncated ", "float16 ", " = ", "Timestamp ", "[<3]", "#")),
    "devicetree": Target("devicetree", "power/supply/battery.yaml", ("$ref: ", "/schemas/types.yaml#/definitions/",
                         "maxItems: ", "items:\n", "- ", "{", "}", "&a ", "*a", "!!python/object ", "enum: [")),
    "devicetree-types": Target("devicetree", "types.yaml", ("string", "value: ", "bits: ", "shape: matrix",
                               "min_items: ", "{", "}", "\n  string: {value: string, bits: 8, shape: scalar}\n")),
    "mavlink": Target("mavlink", "battery.xml", ('<include>x.xml</include>', '<field type="uint8_t" name="a">',
                      "</field>", 'invalid="', 'value="', "<![CDATA[", "&amp;", "<!DOCTYPE x>", '<entry name="E">',
                      "<extensions/>", "char[", "uint64_t[2]")),
    "pdef": Target("params", "battery_failsafe.pdef.xml", ('<param name="BATT_X" humanName="x" documentation="d">',
                   "</param>", '<field name="Range">', "</field>", '<value code="', "<values>", "&lt;", "<!DOCTYPE")),
    "mappings": Target("mappings", "uorb.yaml", ("{op: scale, from: voltage_v, to: pack_voltage}", "op: flags",
                       "map: {}", "unknown: [", "valid_max: ", ".inf", ".nan", "- ", "{", "}", "&a ", "*a")),
    "rules": Target("rules", "uorb-battery-status.yaml", ("expr: ", "cell_count", " and ", " < ", "range(", "sum(",
                    "len(", "- ", "{", "}", "messages: ", "id: ")),
}  # fmt: skip


# -- the inputs ----------------------------------------------------------------------------------

_SPANS = re.compile(r"[0-9]+|[A-Za-z_][A-Za-z0-9_]*")


@st.composite
def mutants(draw: st.DrawFn, seed: str, tokens: tuple[str, ...]) -> str:
    """The seed with one to four edits: spans deleted or repeated, tokens, numbers and names put in,
    lines swapped. Edits at drawn positions, so shrinking finds the smallest breaking edit."""
    text = seed
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(("delete", "repeat", "insert", "number", "name", "swap", "bytes")))
        at = draw(st.integers(0, max(len(text) - 1, 0)))
        if kind == "delete":
            text = text[:at] + text[at + draw(st.integers(1, 200)) :]
        elif kind == "repeat":
            span = text[at : at + draw(st.integers(1, 200))]
            text = text[:at] + span * draw(st.integers(2, 50)) + text[at:]
        elif kind == "insert":
            text = text[:at] + draw(st.sampled_from(tokens)) + text[at:]
        elif kind in ("number", "name"):
            spans = [m for m in _SPANS.finditer(text) if m.group()[0].isdigit() == (kind == "number")]
            if spans:
                m = spans[draw(st.integers(0, len(spans) - 1))]
                new = draw(st.sampled_from(NUMBERS if kind == "number" else NAMES) | st.integers().map(str))
                text = text[: m.start()] + new + text[m.end() :]
        elif kind == "swap":
            lines = text.splitlines(keepends=True)
            if len(lines) > 1:
                i, j = draw(st.integers(0, len(lines) - 1)), draw(st.integers(0, len(lines) - 1))
                lines[i], lines[j] = lines[j], lines[i]
                text = "".join(lines)
        else:
            text = text[:at] + draw(st.text(min_size=1, max_size=20)) + text[at:]
    return text


def random_text() -> st.SearchStrategy[str]:
    return st.text(max_size=400) | st.text(alphabet="<>/=\"' \n[]{}:-#@0123456789abcxyz", max_size=400)


# -- running one input ---------------------------------------------------------------------------


class _Hang(Exception):
    pass


def _alarm(_signum: int, _frame: FrameType | None) -> None:
    raise _Hang("no answer within the time allowed (HANG_SECONDS, RENDER_SECONDS)")


class Workspace:
    """A copy of the schema folders a target needs; each input replaces the victim file."""

    def __init__(self, tmp: Path, name: str) -> None:
        self.name = name
        self.target = TARGETS[name]
        tmp = tmp / name
        self.root = tmp / "schemas"
        whole = self.target.folder in ("mappings", "rules")
        folders = (*FORMATS, "mappings", "rules") if whole else (self.target.folder,)
        for folder in folders:
            shutil.copytree(SCHEMAS / folder, self.root / folder)
        self.victim = self.root / self.target.folder / self.target.victim
        self.seed = self.victim.read_text(encoding="utf-8")
        # mappings and rules are checked against the formats, parsed once
        self.formats: Schema | None = None
        if self.target.folder in ("mappings", "rules"):
            formats_only = tmp / "formats"
            for folder in FORMATS:
                shutil.copytree(SCHEMAS / folder, formats_only / folder)
            self.formats = load_schema_dir(formats_only)
        self.stats: Counter[str] = Counter()

    def parse(self) -> Schema:
        folder = self.root / self.target.folder
        if self.target.folder == "mappings":
            assert self.formats is not None
            return self.formats.merged(mappings.parse_dir(folder, schema=self.formats))
        if self.target.folder == "rules":
            assert self.formats is not None
            schema = self.formats.merged(Schema(rules=rules.load_rules_dir(folder)))
            rules.check_rules(schema)
            return schema
        return load([self.root])

    def check(self, text: str, *, generate: bool = False) -> None:
        """The property, on one input: loads (and generates compiling code) or a BattgenError."""
        self.stats["tried"] += 1
        self.victim.write_text(text, encoding="utf-8", errors="surrogatepass")
        previous = signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, HANG_SECONDS)
        try:
            try:
                schema = self.parse()
            except BattgenError as exc:
                self.stats["refused"] += 1
                assert "Traceback" not in str(exc), exc
                return
            self.stats["accepted"] += 1
            every = COMPILE_EVERY * (3 if self.formats is not None else 1)  # a whole package costs seconds
            if generate or self.stats["accepted"] % every == 0:
                # rendering a whole package takes seconds, and many times that on a loaded machine
                signal.setitimer(signal.ITIMER_REAL, RENDER_SECONDS)
                files = render_package(schema)
                for rel, source in files.items():
                    if rel.endswith(".py"):
                        compile(source, rel, "exec")
                self.stats["generated"] += 1
                self.stats["modules compiled"] += sum(1 for rel in files if rel.endswith(".py"))
        except Exception as exc:
            self.stats["crashed"] += 1
            _save(self.name, self.target, text, exc)
            raise
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)

    def report(self, kind: str) -> None:
        path = os.environ.get("BATTGEN_FUZZ_STATS")
        if path:
            with open(path, "a", encoding="utf-8") as out:
                out.write(json.dumps({"target": f"schema-{self.name}", "inputs": kind, **self.stats}) + "\n")


def _save(name: str, target: Target, text: str, exc: BaseException) -> None:
    """Keep a crashing input (long mode only: CI runs do not write into the repository)."""
    if not LONG:
        return
    ours = [f for f in traceback.extract_tb(exc.__traceback__) if "/codegen/" in f.filename]
    site = type(exc).__name__
    if ours:
        site += f"@{ours[-1].filename.rsplit('/codegen/', 1)[-1]}:{ours[-1].lineno}"
    folder = CRASHERS / f"schema-{name}"
    folder.mkdir(parents=True, exist_ok=True)
    stem = hashlib.sha1(site.encode()).hexdigest()[:12]
    suffix = Path(target.victim).suffix
    # a .uavcan file below tests/ would make the folder look like a DSDL root to `battgen list tests`
    path = folder / f"{stem}{suffix}{'.txt' if suffix == '.uavcan' else ''}"
    if not path.exists() or len(path.read_bytes()) > len(text.encode("utf-8", "surrogatepass")):
        path.write_text(text, encoding="utf-8", errors="surrogatepass")


@pytest.fixture
def workspace(tmp_path: Path) -> Iterator[Callable[[str], Workspace]]:
    made: list[Workspace] = []

    def make(name: str) -> Workspace:
        made.append(Workspace(tmp_path, name))
        return made[-1]

    yield make


# -- the fuzzers -----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_fuzz_schema_mutants(name: str, workspace: Callable[[str], Workspace]) -> None:
    ws = workspace(name)

    @fuzz_settings(ci=CI_MUTANTS.get(name, 30))
    @given(st.data())
    def run(data: st.DataObject) -> None:
        ws.check(data.draw(mutants(ws.seed, ws.target.tokens)))

    try:
        run()
    finally:
        ws.report("mutants")
    assert ws.stats["tried"] > 0 and ws.stats["crashed"] == 0


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_fuzz_schema_random_text(name: str, workspace: Callable[[str], Workspace]) -> None:
    ws = workspace(name)

    # "{[" is not even YAML, so something is refused whatever the draws: YAML without a mapping is
    # no binding to the devicetree frontend (nor to dt-schema), and random text often is such YAML
    @fuzz_settings(ci=10)
    @given(random_text())
    @example("{[")
    def run(text: str) -> None:
        ws.check(text)

    try:
        run()
    finally:
        ws.report("random text")
    assert ws.stats["tried"] > 0
    if name != "devicetree-types":  # a types.yaml without battgen's format line is not ours: the packaged one is used
        assert ws.stats["refused"] > 0  # random text is almost never a schema


REPLAY = [(name, path) for name in sorted(TARGETS) for path in crashers(f"schema-{name}")]


@pytest.mark.parametrize(("name", "path"), REPLAY, ids=[f"{n}/{p.name}" for n, p in REPLAY])
def test_replay_schema_crashers(name: str, path: Path, workspace: Callable[[str], Workspace]) -> None:
    ws = workspace(name)
    ws.check(path.read_text(encoding="utf-8", errors="surrogatepass"), generate=True)


def test_the_seeds_load_and_generate(workspace: Callable[[str], Workspace]) -> None:
    """Each victim file unchanged passes the property: the fuzzers start from valid schemas."""
    for name in sorted(TARGETS):
        ws = workspace(name)
        ws.check(ws.seed, generate=True)
        assert ws.stats["refused"] == 0 and ws.stats["generated"] == 1, name
