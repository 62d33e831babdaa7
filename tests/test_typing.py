"""Everything we write or generate type-checks under mypy --strict: the toolchain, the committed
package, and packages generated from the hand-built schemas of tests/samples.py (hostile names,
every MAVLink field kind, nested uORB messages). One mypy run checks them all; each target is a
case of its own, so a failure names what broke."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT
from samples import NESTED, clashing_schema, hostile_schema, mavlink_thing_xml

from codegen.backends.python.writer import generate
from codegen.frontends import cyphal, dsdl, mavlink, uorb

# target -> the folder whose files mypy reports on
TARGETS = (
    "codegen",
    "generated",
    "hostile",
    "clashing",
    "mavlink_thing",
    "uorb_nested",
    "dronecan_unions",
    "cyphal_unions",
)
# a Cyphal union (held branch, delimited nesting) beside the bundled types, which have none
CYPHAL_UNION = {
    "Empty.1.0.dsdl": "@sealed\n",
    "Pick.1.0.dsdl": "@union\nuint8 small\nfloat16[<=3] halves\ndemo.Empty.1.0 nothing\n@sealed\n",
    "Holder.1.0.dsdl": "demo.Pick.1.0 pick\nuint8[<=4] raw\n@extent 256\n",
}


def _generate_samples(root: Path) -> None:
    generate(hostile_schema(), root / "hostile")
    generate(clashing_schema(), root / "clashing")
    work = root / "sources"
    work.mkdir()
    generate(mavlink.parse_file(mavlink_thing_xml(work), root=work), root / "mavlink_thing")
    msgs = work / "msg"
    msgs.mkdir()
    for name, text in NESTED.items():
        (msgs / name).write_text(text, encoding="utf-8")
    generate(uorb.parse_dir(msgs), root / "uorb_nested")
    # DroneCAN unions (param.Value inside GetSet, NumericValue): the types pydronecan ships
    specs = Path(pytest.importorskip("dronecan").__file__).parent / "dsdl_specs"
    generate(
        dsdl.parse_file(specs / "uavcan" / "protocol" / "param" / "11.GetSet.uavcan", root=specs),
        root / "dronecan_unions",
    )
    (work / "cyphal" / "demo").mkdir(parents=True)
    for name, text in CYPHAL_UNION.items():
        (work / "cyphal" / "demo" / name).write_text(text, encoding="utf-8")
    generate(cyphal.parse_dir(work / "cyphal"), root / "cyphal_unions")


@pytest.fixture(scope="module")
def mypy_report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[str]]:
    """Run mypy once over every target; its error lines, by target."""
    samples = tmp_path_factory.mktemp("typed")
    _generate_samples(samples)
    # the project's configuration (strict, and the reference stacks without stubs) for all targets
    command = [sys.executable, "-m", "mypy", "--no-incremental", "--config-file", str(ROOT / "pyproject.toml")]
    for target in TARGETS:
        command += ["-p", target]
    proc = subprocess.run(
        command,
        cwd=ROOT,
        env={**os.environ, "MYPYPATH": str(samples)},  # where the sample packages are found
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode in (0, 1), proc.stdout + proc.stderr  # 2: mypy itself failed
    report: dict[str, list[str]] = {t: [] for t in TARGETS}
    places = {"codegen": ROOT / "codegen", "generated": ROOT / "generated"}
    places |= {t: samples / t for t in TARGETS[2:]}
    for line in proc.stdout.splitlines():
        match = re.match(r"(.+?):\d+: (error|note)", line)
        if match is None:
            continue
        path = (ROOT / match.group(1)).resolve()
        owner = next((t for t, folder in places.items() if path.is_relative_to(folder.resolve())), None)
        report.setdefault(owner or "elsewhere", []).append(line)
    report["summary"] = [proc.stdout.strip().splitlines()[-1]] if proc.stdout.strip() else []
    return report


@pytest.mark.parametrize("target", [*TARGETS, "elsewhere"])
def test_mypy_strict(mypy_report: dict[str, list[str]], target: str) -> None:
    assert mypy_report.get(target, []) == [], "\n".join(mypy_report[target] + mypy_report["summary"])
