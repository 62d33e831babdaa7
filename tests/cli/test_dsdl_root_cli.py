"""``battgen list`` / ``generate`` pointed at a DSDL root (the ``dronecan`` package's ``dsdl_specs``, whose
top folders are namespaces, one of them named ``dronecan/``), and the error for a folder inside one."""

from __future__ import annotations

import importlib
import shutil
import sys
from pathlib import Path

import pytest

from codegen.cli.main import main

dronecan = pytest.importorskip("dronecan")
SPECS = Path(dronecan.__file__).parent / "dsdl_specs"


def test_list_reads_the_whole_dsdl_root_with_dsdl_names(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["list", str(SPECS)]) == 0
    names = capsys.readouterr().out.split()
    assert "dronecan.cuav.equipment.power.CBAT" in names
    assert "dronecan.com.tmotor.esc.PUSHCAN" in names
    assert "dronecan.dronecan.protocol.Stats" in names  # the namespace called dronecan
    assert "dronecan.uavcan.protocol.param.GetSet.Request" in names


@pytest.mark.parametrize("inside", ["dronecan", "uavcan", "uavcan/equipment/power"])
def test_a_folder_inside_a_dsdl_root_names_the_root(capsys: pytest.CaptureFixture[str], inside: str) -> None:
    assert main(["list", str(SPECS / inside)]) == 2
    err = capsys.readouterr().err
    assert "a DSDL namespace folder, not a DSDL root" in err
    assert err.rstrip().endswith(f"pass the folder holding its top namespace, {SPECS}")
    assert "Traceback" not in err


def test_generate_a_dsdl_root_keeps_dsdl_names(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = tmp_path / "dsdl"
    shutil.copytree(SPECS / "cuav", root / "cuav")
    shutil.copytree(SPECS / "com" / "tmotor", root / "com" / "tmotor")
    assert main(["generate", str(root), "--out", str(tmp_path / "dcroot")]) == 0
    sys.path.insert(0, str(tmp_path))
    try:
        power = importlib.import_module("dcroot.dronecan.cuav.equipment.power")
        esc = importlib.import_module("dcroot.dronecan.com.tmotor.esc")
        assert power.CBAT.QUALIFIED_NAME == "dronecan.cuav.equipment.power.CBAT"
        assert esc.PUSHCAN.QUALIFIED_NAME == "dronecan.com.tmotor.esc.PUSHCAN"
    finally:
        sys.path.remove(str(tmp_path))
        for name in [n for n in sys.modules if n.split(".")[0] == "dcroot"]:
            del sys.modules[name]


def test_a_folder_with_no_schemas_says_what_it_expected(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["list", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "not a schema folder" in err and "nor a DSDL root" in err
