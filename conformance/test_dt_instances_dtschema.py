"""Devicetree instances against the reference tools: dtc (Debian's device-tree-compiler) and
dtschema's dt-validate.

(a) our .dts parser and our .dtb reader give the same nodes, byte for byte, on every test file
    compiled by dtc, and on dtc's own decompilation (dtc -I dtb -O dts) re-read by us;
(b) on the binding examples dt-extract-example pulls out of dtschema's schemas and ours, our
    parser and dtc accept and refuse the same inputs and agree on every accepted one;
(c) for every simple-battery node, our verdict (node_to_model_dict + generated from_dict + the
    binding's own checks) names the same failing properties as dt-validate run with a schema
    processed by dt-mk-schema from schemas/devicetree -- empty for the valid_* files.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

from codegen.frontends import devicetree as frontend
from codegen.inputs.devicetree import (
    DevicetreeError,
    DtNode,
    find_compatible,
    monitored_batteries,
    node_to_model_dict,
    read_dtb,
    read_dts,
)
from codegen.ir import ArrayType, Message, Range
from generated._meta import DataError
from generated.devicetree.power.supply import SimpleBattery

dtschema = pytest.importorskip("dtschema")
DTC = shutil.which("dtc")
if DTC is None and os.environ.get("CI"):
    # CI installs dtc (.ci/run); there a missing compiler is a failure, not a reason to skip the peer comparison.
    raise RuntimeError("dtc is not installed: .ci/run must install device-tree-compiler")
pytestmark = pytest.mark.skipif(DTC is None, reason="dtc not installed (apt-get install device-tree-compiler)")

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data" / "devicetree"
SCHEMAS = ROOT / "schemas" / "devicetree"
BATTERY_YAML = SCHEMAS / "power" / "supply" / "battery.yaml"
BIN = Path(sys.executable).parent
CASES = sorted(p.name for p in DATA.glob("*.dts"))


def _run(args: list[str], **kw: Any) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, capture_output=True, text=True, timeout=120, **kw)


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("dtb")
    result: dict[str, Path] = {}
    for name in CASES:
        dtb = out / name.replace(".dts", ".dtb")
        done = _run([str(DTC), "-q", "-I", "dts", "-O", "dtb", "-o", str(dtb), str(DATA / name)])
        assert done.returncode == 0, f"dtc refused our test file {name}: {done.stderr}"
        result[name] = dtb
    return result


@pytest.fixture(scope="module")
def message() -> Message:
    return frontend.parse_dir(SCHEMAS).message("devicetree.power.supply.battery")


@pytest.fixture(scope="module")
def diagnostics(compiled: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Any]:
    """dt-validate's diagnostics per (dtb file name, node path), all files in one run."""
    work = tmp_path_factory.mktemp("dtschema")
    processed = work / "processed.json"
    done = _run([str(BIN / "dt-mk-schema"), "-j", "-o", str(processed), str(SCHEMAS)])
    assert done.returncode == 0 and processed.stat().st_size > 0, done.stderr
    report = work / "report.json"
    _run([str(BIN / "dt-validate"), "-s", str(processed), "--json-output", str(report), *map(str, compiled.values())])
    grouped: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for diag in json.loads(report.read_text()):
        if diag.get("type") == "validation":
            grouped.setdefault((Path(diag["file"]).name, diag["node"]), []).append(diag)
    return grouped


def _raw(nodes: list[DtNode]) -> list[tuple[str, dict[str, bytes]]]:
    return [(n.path, n.raw()) for n in nodes]


# (a) ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", CASES)
def test_dts_parser_and_dtb_reader_agree(name: str, compiled: dict[str, Path], message: Message) -> None:
    ours = read_dts(DATA / name)
    blob = read_dtb(compiled[name])
    assert _raw(ours) == _raw(blob)
    assert len(ours) >= 2
    for a, b in zip(find_compatible(ours, "simple-battery"), find_compatible(blob, "simple-battery"), strict=True):
        assert node_to_model_dict(a, message) == node_to_model_dict(b, message)


@pytest.mark.parametrize("name", CASES)
def test_dtc_decompiled_source_reads_the_same(name: str, compiled: dict[str, Path], tmp_path: Path) -> None:
    back = tmp_path / "back.dts"
    done = _run([str(DTC), "-q", "-I", "dtb", "-O", "dts", "-o", str(back), str(compiled[name])])
    assert done.returncode == 0, done.stderr
    assert _raw(read_dts(back)) == _raw(read_dtb(compiled[name]))


# (b) ----------------------------------------------------------------------------------------


def _example_sources() -> list[Path]:
    pkg = Path(dtschema.__file__).resolve().parent / "schemas"
    files = [p for p in sorted(pkg.rglob("*.yaml")) if "\nexamples:" in p.read_text(encoding="utf-8")]
    return [BATTERY_YAML, *files]


@pytest.mark.parametrize("schema", _example_sources(), ids=lambda p: p.name)
def test_binding_examples_parse_like_dtc(schema: Path, tmp_path: Path) -> None:
    done = _run([str(BIN / "dt-extract-example"), str(schema)])
    assert done.returncode == 0, done.stderr
    # The wrapper declares /plugin/ to tolerate dangling references; we read whole trees only.
    source = tmp_path / "example.dts"
    source.write_text(re.sub(r"^/plugin/;.*$", "", done.stdout, flags=re.M))
    if "#include" in done.stdout or re.search(r"\b[A-Z][A-Z0-9_]{3,}\b", done.stdout):
        if shutil.which("cpp") is None:
            pytest.skip("example may need the C preprocessor and cpp is not installed")
        pre = _run(
            ["cpp", "-nostdinc", "-undef", "-x", "assembler-with-cpp", "-o", str(tmp_path / "pp.dts"), str(source)]
        )
        if pre.returncode != 0:
            with pytest.raises(DevicetreeError, match="C preprocessor"):
                read_dts(source)
            pytest.skip(f"example needs headers we do not have: {pre.stderr.strip()[:120]}")
        source = tmp_path / "pp.dts"
    dtb = tmp_path / "example.dtb"
    built = _run([str(DTC), "-q", "-I", "dts", "-O", "dtb", "-o", str(dtb), str(source)])
    if built.returncode != 0:
        with pytest.raises(DevicetreeError):
            read_dts(source)
        return
    assert _raw(read_dts(source)) == _raw(read_dtb(dtb))


# (c) ----------------------------------------------------------------------------------------


def _column_maxima() -> dict[str, dict[int, int]]:
    """Per-column maxima of matrix properties, read from the binding YAML (the IR keeps one range
    per field, so ``items: items: [{}, {maximum: 100}]`` is checked from the source here)."""
    doc = yaml.safe_load(BATTERY_YAML.read_text())
    out: dict[str, dict[int, int]] = {}
    for group in ("properties", "patternProperties"):
        for name, spec in (doc.get(group) or {}).items():
            outer = (spec or {}).get("items")
            columns = outer.get("items") if isinstance(outer, dict) else None
            if isinstance(columns, list):
                limits = {i: c["maximum"] for i, c in enumerate(columns) if isinstance(c, dict) and "maximum" in c}
                if limits:
                    out[name] = limits
    return out


def _leaves(value: Any) -> list[int]:
    if isinstance(value, list):
        return [x for v in value for x in _leaves(v)]
    return [value] if isinstance(value, int) else []


def _out_of_range(values: list[int], r: Range) -> bool:
    return any((r.minimum is not None and v < r.minimum) or (r.maximum is not None and v > r.maximum) for v in values)


def our_failures(node: DtNode, message: Message) -> set[str]:
    """Properties our side rejects: generated from_dict, then the binding's own facts from the IR
    (required, const, enum, range) and the YAML's per-column maxima. Kept independent of the
    generated validate(), which test_validate_agrees_with_dtschema compares on its own."""
    data = node_to_model_dict(node, message)
    try:
        SimpleBattery.from_dict(data)
    except DataError as exc:
        return {re.split(r"[\[.]", exc.path.removeprefix("SimpleBattery."), maxsplit=1)[0]}
    failed: set[str] = set()
    info = message.devicetree
    assert info is not None
    failed |= {name for name in info.required if name not in data}
    maxima = _column_maxima()
    for name, value in data.items():
        f = next(f for f in message.fields if f.name == name or (f.pattern and re.search(f.pattern, name)))
        if f.const is not None and value != ([f.const] if isinstance(f.type, ArrayType) else f.const):
            failed.add(name)
        if f.choices and value not in f.choices:
            failed.add(name)
        if f.range is not None and _out_of_range(_leaves(value), f.range):
            failed.add(name)
        for column, limit in maxima.get(f.name, {}).items():
            if any(len(row) > column and row[column] > limit for row in value):
                failed.add(name)
    return failed


def dtschema_failures(diags: list[dict[str, Any]]) -> set[str]:
    failed: set[str] = set()
    for d in diags:
        if d["property_path"]:
            failed.add(str(d["property_path"][0]))
        else:
            failed |= set(re.findall(r"'([^']+)' (?:does not match any|is a required property)", d["message"]))
    return failed


@pytest.mark.parametrize("name", CASES)
def test_verdict_agrees_with_dt_validate(
    name: str, compiled: dict[str, Path], diagnostics: dict[tuple[str, str], Any], message: Message
) -> None:
    dtb_name = compiled[name].name
    for nodes in (read_dts(DATA / name), read_dtb(compiled[name])):
        batteries = find_compatible(nodes, "simple-battery")
        if name == "invalid_missing_compatible.dts":
            # dt-schema selects a binding by compatible: it is silent about this node, and so is
            # find_compatible; checked as a battery (it is one, by monitored-battery) it fails.
            assert batteries == []
            (_, battery), *_ = monitored_batteries(nodes)
            assert diagnostics.get((dtb_name, battery.path)) is None
            assert our_failures(battery, message) == {"compatible"}
            continue
        assert len(batteries) == 1
        theirs = dtschema_failures(diagnostics.get((dtb_name, batteries[0].path), []))
        ours = our_failures(batteries[0], message)
        assert ours == theirs, f"{name}: ours {ours}, dt-validate {theirs}"
        assert bool(ours) == name.startswith("invalid_")


@pytest.mark.parametrize("name", CASES)
def test_validate_agrees_with_dtschema(
    name: str, compiled: dict[str, Path], diagnostics: dict[tuple[str, str], Any], message: Message
) -> None:
    """The generated validate() against dt-validate (skips where the generated package predates it)."""
    if not hasattr(SimpleBattery, "validate"):
        pytest.skip("SimpleBattery.validate() is not generated: run battgen generate")
    nodes = read_dts(DATA / name)
    batteries = find_compatible(nodes, "simple-battery") or [b for _, b in monitored_batteries(nodes)]
    for node in batteries:
        try:
            model = SimpleBattery.from_dict(node_to_model_dict(node, message))
        except DataError:
            continue  # refused before validate() can run; test_verdict_agrees_with_dt_validate covers it
        violations = model.validate()
        errors = {re.split(r"[\[.]", v.path, maxsplit=1)[0] for v in violations if v.severity == "error"}
        theirs = dtschema_failures(diagnostics.get((compiled[name].name, node.path), []))
        if name == "invalid_missing_compatible.dts":
            assert theirs == set() and "compatible" in errors
        else:
            assert errors == theirs, f"{name}: validate() {errors}, dt-validate {theirs}"
