"""Malformed and hostile schemas end with one clear line and exit 2 (issue 10, items 3, 4, 6 and 9).

Each case is one fixture: a copy of a bundled schema folder with one defect, the message expected
(file, line, what was expected) and nothing else. The cases that once hung or grew without bound run
the CLI in a child process with an address-space limit, and report its peak memory and wall time
against generous margins (never a timing assertion on the fast path).
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from conftest import ROOT

from codegen.cli.main import main
from codegen.ir.fieldtypes import MAX_ARRAY_CAPACITY
from codegen.text.limits import MAX_NUMBER_DIGITS, MAX_XML_DEPTH, MAX_XML_TEXT

BIG = "1" * 5000  # over Python's 4,300-digit limit for int()
SCHEMAS = ROOT / "schemas"
# the line of BatteryStatus.msg the uORB case edits (max_error's range)
MAX_ERROR_LINE = next(
    n
    for n, line in enumerate((SCHEMAS / "uorb" / "BatteryStatus.msg").read_text().splitlines(), 1)
    if "max_error" in line
)


@dataclass(frozen=True)
class Case:
    make: Callable[[Path], None]  # writes the defect into a copy of schemas/<format>/
    formats: tuple[str, ...]  # the sub-folders copied
    message: str  # a regular expression for the whole stderr line after "battgen: "


def _edit(rel: str, old: str, new: str, count: int = 1) -> Callable[[Path], None]:
    def make(root: Path) -> None:
        path = root / rel
        text = path.read_text(encoding="utf-8")
        assert old in text, f"{rel}: {old!r} not found"
        path.write_text(text.replace(old, new, count), encoding="utf-8")

    return make


def _sub(rel: str, pattern: str, new: str) -> Callable[[Path], None]:
    def make(root: Path) -> None:
        path = root / rel
        text, n = re.subn(pattern, new, path.read_text(encoding="utf-8"), count=1)
        assert n == 1, f"{rel}: {pattern!r} not found"
        path.write_text(text, encoding="utf-8")

    return make


def _both(*makes: Callable[[Path], None]) -> Callable[[Path], None]:
    def make(root: Path) -> None:
        for one in makes:
            one(root)

    return make


def _write(rel: str, text: str) -> Callable[[Path], None]:
    def make(root: Path) -> None:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")

    return make


DIGITS = rf"expected a number of at most {MAX_NUMBER_DIGITS} digits \(docs/limits.md\), got one of 5000 digits"
TIMESTAMP = "uint64 timestamp # [us] Time since system start"
MAVLINK = "mavlink/battery.xml"
PDEF = "params/battery_failsafe.pdef.xml"
DT = "devicetree/power/supply/battery.yaml"
UORB_MAP = "mappings/uorb.yaml"
CAPACITY = "to: full_capacity, unknown: [0]}"
ALL = ("uorb", "dronecan", "devicetree", "mavlink", "cyphal", "params", "mappings", "rules")  # mappings name them all
OTHER_XML = _write("outside/other.xml", "<mavlink/>")
EMPTY_FLAGS = "{op: flags, from: faults, to: faults, map: {}}"
SCALE_V = "{op: scale, from: voltage_v, to: pack_voltage}"

# item 3: tracebacks on malformed schemas
CASES: dict[str, Case] = {
    "uorb-range-huge-integer": Case(
        _edit("uorb/BatteryStatus.msg", "[@range 1, 100]", f"[@range 1, {BIG}]"),
        ("uorb",),
        rf"BatteryStatus\.msg:{MAX_ERROR_LINE}: {DIGITS}",
    ),
    "dsdl-type-huge-integer": Case(
        _write("dronecan/ns/Big.uavcan", f"uint{BIG} x\n"), ("dronecan",), rf"ns/Big\.uavcan:1: {DIGITS}"
    ),
    "dsdl-array-huge-integer": Case(
        _write("dronecan/ns/Big.uavcan", f"uint8[{BIG}] x\n"), ("dronecan",), rf"ns/Big\.uavcan:1: {DIGITS}"
    ),
    "dsdl-constant-huge-integer": Case(
        _write("dronecan/ns/Big.uavcan", f"uint8 X = {BIG}\n"), ("dronecan",), rf"ns/Big\.uavcan:1: {DIGITS}"
    ),
    "devicetree-yaml-huge-integer": Case(
        _edit(DT, "maxItems: 100", f"maxItems: {BIG}"), ("devicetree",), rf"power/supply/battery\.yaml:\d+: {DIGITS}"
    ),
    "devicetree-types-without-string": Case(
        _edit("devicetree/types.yaml", "\n  string: ", "\n  strong: "),
        ("devicetree",),
        r"power/supply/battery\.yaml:\d+: expected types\.yaml to define 'string', the type of property '[a-z-]+'",
    ),
    "pdef-unknown-xml-encoding": Case(
        _edit(PDEF, 'encoding="utf-8"', 'encoding="klingon"'),
        ("params",),
        r"battery_failsafe\.pdef\.xml:1: expected encoding=\"UTF-8\" in the XML declaration .*got 'klingon'",
    ),
    "mavlink-unknown-xml-encoding": Case(
        _edit(MAVLINK, '<?xml version="1.0"?>', '<?xml version="1.0" encoding="x-unknown"?>'),
        ("mavlink",),
        r"battery\.xml:1: expected encoding=\"UTF-8\" in the XML declaration .*got 'x-unknown'",
    ),
    "mavlink-invalid-1e999": Case(
        _edit(MAVLINK, 'invalid="INT16_MAX"', 'invalid="1e999"'),
        ("mavlink",),
        r"battery\.xml:\d+: expected an invalid value that fits int16, got '1e999'",
    ),
    # item 9: includes stay in the schema folder
    "mavlink-include-etc-passwd": Case(
        _edit(MAVLINK, "<mavlink>", "<mavlink>\n<include>/etc/passwd</include>"),
        ("mavlink",),
        r"battery\.xml:\d+: expected an include inside the schema folder \(.*\); /etc/passwd is outside it "
        r"\(allow its folder with --include-path\)",
    ),
    "mavlink-include-dot-dot": Case(
        _both(_edit(MAVLINK, "<mavlink>", "<mavlink>\n<include>../outside/other.xml</include>"), OTHER_XML),
        ("mavlink",),
        r"battery\.xml:\d+: expected an include inside the schema folder .*\.\./outside/other\.xml is outside it .*",
    ),
    # item 6: whatever ir accepts must generate
    "mapping-flags-empty-map": Case(
        _sub(UORB_MAP, r"      - op: flags\n.*\n.*\n        map:\n(          .*\n)+", f"      - {EMPTY_FLAGS}\n"),
        ALL,
        r"uorb\.yaml:\d+: expected a valid mapping file at mappings/0/rules/\d+/map: \{\} should be non-empty",
    ),
    "mapping-infinite-bound": Case(
        _edit(UORB_MAP, CAPACITY, CAPACITY.replace("}", ", valid_max: .inf}")),
        ALL,
        r"uorb\.yaml:21: expected a finite number for 'valid_max', got inf",
    ),
    "mapping-string-bound": Case(
        _edit(UORB_MAP, CAPACITY, CAPACITY.replace("}", ", valid_max: abc}")),
        ALL,
        r"uorb\.yaml:21: expected a valid mapping file at .*/valid_max: 'abc' is not of type 'number'",
    ),
    "mapping-incompatible-unit": Case(
        _edit(UORB_MAP, SCALE_V, SCALE_V.replace("voltage_v", "current_a")),
        ALL,
        r"uorb\.yaml:12: expected units of one quantity for op 'scale', got A \(current\) and V \(voltage\)",
    ),
}  # fmt: skip


def _schema_copy(tmp_path: Path, case: Case) -> Path:
    root = tmp_path / "schemas"
    for fmt in case.formats:
        shutil.copytree(SCHEMAS / fmt, root / fmt)
    case.make(root)
    return root


@pytest.mark.parametrize("name", sorted(CASES))
def test_malformed_schema_is_one_clear_line(name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    case = CASES[name]
    root = _schema_copy(tmp_path, case)
    for command in (["ir", str(root)], ["generate", str(root), "--out", str(tmp_path / "pkg")]):
        code = main(command)
        out, err = capsys.readouterr()
        assert code == 2, (command, out[-500:], err)
        assert "Traceback" not in err and len(err.splitlines()) == 1, err
        assert re.fullmatch(rf"battgen: {case.message}\n", err), err
        assert not (tmp_path / "pkg").exists()  # nothing written from a schema that failed


def test_include_path_allows_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An include outside the schema folder reads once the user names its folder with --include-path."""
    root = _schema_copy(tmp_path, CASES["mavlink-include-dot-dot"])
    outside = root / "outside"
    (outside / "other.xml").write_text(
        '<?xml version="1.0"?>\n<mavlink>\n<messages>\n<message id="250" name="OTHER">\n<description>d</description>\n'
        '<field type="uint8_t" name="x">x</field>\n</message>\n</messages>\n</mavlink>\n',
        encoding="utf-8",
    )
    assert main(["list", str(root)]) == 2
    assert "is outside it" in capsys.readouterr().err
    assert main(["list", str(root), "--include-path", str(outside)]) == 0
    names = capsys.readouterr().out.split()
    assert "mavlink.OTHER" in names and "mavlink.BATTERY_STATUS" in names
    # the search path is searched too: a bare file name found there
    (root / "mavlink" / "battery.xml").write_text(
        (root / "mavlink" / "battery.xml").read_text(encoding="utf-8").replace("../outside/other.xml", "other.xml"),
        encoding="utf-8",
    )
    assert main(["list", str(root), "--include-path", str(outside)]) == 0
    assert "mavlink.OTHER" in capsys.readouterr().out.split()


# item 4: schemas that hung or ran out of memory, run in a child process with an address-space limit

LIMIT_BYTES = 2 * 1024**3  # far above what these need once refused (~100 MB), far below the old blow-ups


@dataclass(frozen=True)
class Bounded:
    code: int
    stderr: str
    seconds: float
    peak_mb: float


# the child reports its own peak RSS (RUSAGE_CHILDREN would mix in every earlier child of this process)
_CHILD = """import os, resource, sys
from codegen.cli.main import main
try:
    code = main(sys.argv[1:])
finally:
    with open(os.environ["BATTGEN_PEAK_FILE"], "w") as out:
        out.write(str(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))
sys.exit(code)
"""


def _bounded_cli(args: list[str], peak_file: Path, timeout: float = 300) -> Bounded:
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (LIMIT_BYTES, LIMIT_BYTES))

    started = time.monotonic()
    try:
        proc = subprocess.run(
            [sys.executable, "-c", _CHILD, *args],
            cwd=ROOT,
            env={**os.environ, "BATTGEN_PEAK_FILE": str(peak_file)},
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=timeout,
            preexec_fn=limit,  # only sets a resource limit in the child
            check=False,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"battgen {' '.join(args)} still running after {timeout} s")
    peak_kb = int(peak_file.read_text()) if peak_file.exists() else -1
    return Bounded(proc.returncode, proc.stderr, time.monotonic() - started, peak_kb / 1024)


def _mavlink_with(tmp_path: Path, insert: str) -> Path:
    root = tmp_path / "schemas"
    shutil.copytree(SCHEMAS / "mavlink", root / "mavlink")
    path = root / MAVLINK
    text = path.read_text(encoding="utf-8")
    path.write_text(text.replace("<description>", "<description>" + insert, 1), encoding="utf-8")
    return root


def _copy_with(make: Callable[[Path], None], *formats: str) -> Callable[[Path], Path]:
    return lambda tmp: _schema_copy(tmp, Case(make, formats, ""))


CAPACITY_LIMIT = f"at most {MAX_ARRAY_CAPACITY} \\(docs/limits.md\\)"
HANGS: dict[str, tuple[Callable[[Path], Path], str]] = {
    "mavlink-100000-nested-tags": (
        lambda tmp: _mavlink_with(tmp, "<a>" * 100_000 + "</a>" * 100_000),
        rf"battery\.xml:\d+: expected elements nested at most {MAX_XML_DEPTH} deep \(docs/limits.md\)",
    ),
    "mavlink-huge-text": (
        lambda tmp: _mavlink_with(tmp, "x\n" * 2_000_000),
        rf"battery\.xml:\d+: expected at most {MAX_XML_TEXT} characters of text in one element \(docs/limits.md\)",
    ),
    "pdef-640k-lines-of-text": (
        _copy_with(_edit(PDEF, '<field name="Type">', '<field name="Type">' + "y\n" * 640_000), "params"),
        rf"battery_failsafe\.pdef\.xml:\d+: expected at most {MAX_XML_TEXT} characters of text in one element",
    ),
    "dsdl-array-of-9999999999": (
        _copy_with(_write("dronecan/ns/Big.uavcan", "uint8[9999999999] x\n"), "dronecan"),
        rf"ns/Big\.uavcan:1: expected an array capacity of {CAPACITY_LIMIT}, got \[9999999999\]",
    ),
    "uorb-array-of-9999999999": (
        _copy_with(_write("uorb/Big.msg", f"{TIMESTAMP}\nuint8[9999999999] x\n"), "uorb"),
        rf"Big\.msg:2: expected an array size of {CAPACITY_LIMIT}, got 9999999999",
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", sorted(HANGS))
def test_schema_that_hung_is_refused_in_bounded_time_and_memory(name: str, tmp_path: Path) -> None:
    make, message = HANGS[name]
    root = make(tmp_path)
    result = _bounded_cli(["generate", str(root), "--out", str(tmp_path / "pkg")], tmp_path / "peak")
    assert result.code == 2, result.stderr[-2000:]
    assert re.fullmatch(rf"battgen: {message}.*\n", result.stderr), result.stderr[-2000:]
    # generous margins: the refusals take about a second and 100 MB; the blow-ups took minutes and gigabytes
    assert 0 < result.peak_mb < 1024, f"peak RSS {result.peak_mb:.0f} MB"
    assert result.seconds < 120, f"{result.seconds:.0f} s"
