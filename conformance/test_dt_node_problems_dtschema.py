"""Every problem of a devicetree battery node, as dt-validate reports it: same problems, same order.

Cases: real kernel battery nodes (../shared/corpus/upstream/linux_batteries/, see its SOURCE.md), our
devicetree test files (tests/data/devicetree/) and nodes with several problems at once. Each side's
report becomes a list of (kind, property): ``unknown`` for the one additionalProperties problem
(with every name it lists), ``raw`` for dt-core's "not of type" on a value that stayed bytes,
``unit`` for property-units' one, ``binding`` for the battery binding's own. battgen's cross-field
rules go beyond dt-schema and are left out of the comparison (they are warnings on these nodes).
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
from shared_data import UPSTREAM

from codegen.apps.gate.validate import Finding, check_file, make_checker
from codegen.inputs.devicetree import find_compatible, read_dts

pytest.importorskip("dtschema")
DTC = shutil.which("dtc")
if DTC is None and os.environ.get("CI"):
    raise RuntimeError("dtc is not installed: .ci/run must install device-tree-compiler")
pytestmark = pytest.mark.skipif(DTC is None, reason="dtc not installed (apt-get install device-tree-compiler)")

ROOT = Path(__file__).resolve().parent.parent
CORPUS = UPSTREAM / "linux_batteries"
DATA = ROOT / "tests" / "data" / "devicetree"
BIN = Path(sys.executable).parent
BATTERY = "devicetree.power.supply.battery"

# Nodes with several problems at once (the issue's case first: two unknown properties, one
# untyped, and an OCV percent out of range).
MULTI = {
    "multi_unknown_and_ocv.dts": """
        acme,secret-sauce = <1>;
        other-sauce-microvolt = <2>;
        ocv-capacity-celsius = <20>;
        ocv-capacity-table-0 = <4200000 101>, <3700000 50>, <3300000 0>;""",
    "multi_everything.dts": """
        device-chemistry = "lead-acid";
        acme,b = "text";
        operating-range-celsius = <(-20) 40 60>;
        voltage-min-design-microvolt = "3.2 V";
        acme,a;
        ocv-capacity-celsius = <20 30>;
        ocv-capacity-table-1 = <4200000 100>, <3700000 101>;
        ocv-capacity-table-0 = <4200000 102>, <3700000>;""",
}


def _cases(tmp: Path) -> list[Path]:
    files = sorted(CORPUS.glob("*.dts")) + sorted(DATA.glob("*.dts"))
    for name, body in MULTI.items():
        path = tmp / name
        path.write_text(f'/dts-v1/;\n/ {{\n\tbattery {{\n\t\tcompatible = "simple-battery";{body}\n\t}};\n}};\n')
        files.append(path)
    return files


def _run(args: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, dict[str, list[Any]]]]:
    """Per case: its .dts and dt-validate's diagnostics per node path (all files in one run)."""
    work = tmp_path_factory.mktemp("dtnodes")
    processed = work / "processed.json"
    done = _run([str(BIN / "dt-mk-schema"), "-j", "-o", str(processed), str(ROOT / "schemas" / "devicetree")])
    assert done.returncode == 0, done.stderr
    dtbs: dict[str, Path] = {}
    cases = {p.name: p for p in _cases(work)}
    for name, source in cases.items():
        dtb = work / (name + ".dtb")
        built = _run([str(DTC), "-q", "-I", "dts", "-O", "dtb", "-i", str(source.parent), "-o", str(dtb), str(source)])
        assert built.returncode == 0, f"{name}: {built.stderr}"
        dtbs[dtb.name] = dtb
    report = work / "report.json"
    _run([str(BIN / "dt-validate"), "-s", str(processed), "--json-output", str(report), *map(str, dtbs.values())])
    grouped: dict[str, dict[str, list[Any]]] = {name: {} for name in cases}
    for diag in json.loads(report.read_text()):
        if diag.get("type") == "validation":
            name = Path(diag["file"]).name.removesuffix(".dtb")
            grouped[name].setdefault(diag["node"], []).append(diag)
    return {name: (cases[name], grouped[name]) for name in cases}


def theirs(diags: list[dict[str, Any]]) -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    for d in diags:
        schema = d["schema"].rsplit("/", 1)[-1]
        if d["schema_path"] and d["schema_path"][-1] == "additionalProperties":
            out.append(("unknown", tuple(re.findall(r"'([^']+)'", d["message"].split(" do")[0]))))
        elif schema == "dt-core.yaml":
            out.append(("raw", d["property_path"][0]))
        elif schema == "property-units.yaml":
            out.append(("unit", d["property_path"][0]))
        elif d["property_path"]:
            out.append(("binding", d["property_path"][0]))
        else:
            out.append(("binding", tuple(re.findall(r"'([^']+)' is a required property", d["message"]))))
    return out


def ours(findings: list[Finding], node: str) -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    for f in findings:
        if f.where != node or f.rule.startswith("cross-field:"):
            continue
        top = re.split(r"\[", f.path, maxsplit=1)[0]
        if f.rule == "additional-properties":
            out.append(("unknown", tuple(f.value)))  # type: ignore[arg-type]
        elif f.rule == "dt-core-type":
            out.append(("raw", top))
        elif f.rule == "unit-type":
            out.append(("unit", top))
        elif top:
            out.append(("binding", top))
    return out


@pytest.fixture(scope="module")
def checker() -> Any:
    return make_checker(ROOT / "schemas", BATTERY)


def _names() -> list[str]:
    return [p.name for p in sorted(CORPUS.glob("*.dts")) + sorted(DATA.glob("*.dts"))] + sorted(MULTI)


@pytest.mark.parametrize("name", _names())
def test_every_problem_in_dt_validates_order(name: str, reports: Any, checker: Any) -> None:
    source, by_node = reports[name]
    message, check = checker
    report = check_file(source, message, check)
    assert not report.unreadable
    battery_nodes = {n.path for n in find_compatible(read_dts(source), "simple-battery")}
    for node in sorted(battery_nodes):
        want = theirs(by_node.get(node, []))
        got = ours(report.findings, node)
        assert got == want, f"{name} {node}: battgen {got}, dt-validate {want}"
    errors = [f for f in report.findings if f.severity == "error"]
    dt_errors = [d for n in battery_nodes for d in by_node.get(n, [])]
    assert bool(errors) == bool(dt_errors), name  # the verdict


def test_the_issues_case_counts_three_on_both_sides(reports: Any, checker: Any) -> None:
    source, by_node = reports["multi_unknown_and_ocv.dts"]
    message, check = checker
    got = ours(check_file(source, message, check).findings, "/battery")
    assert (
        got
        == theirs(by_node["/battery"])
        == [
            ("unknown", ("acme,secret-sauce", "other-sauce-microvolt")),
            ("binding", "ocv-capacity-table-0"),
            ("raw", "acme,secret-sauce"),
        ]
    )


def test_corpus_holds_a_real_rejected_node(reports: Any) -> None:
    _, by_node = reports["sp9860g-1h10-before-fix.dts"]
    assert len(by_node["/battery"]) == 2
    valid = [name for name in reports if name.startswith("rk3") or name == "sp9860g-1h10.dts"]
    assert len(valid) == 3 and all(not reports[name][1].get("/battery") for name in valid)
