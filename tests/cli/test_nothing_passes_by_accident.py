"""Inputs that hold nothing are not a pass, and bad output paths are one clear line (exit 2, no
traceback): failsafe and params --check without BATT*_ parameters, a stream without samples,
generate and docs --out onto a file. (validate and convert: test_validate_cli / test_convert_logs.)"""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.cli.main import main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_params_check_without_batt_parameters(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    empty, other = tmp_path / "empty.param", tmp_path / "other.param"
    empty.write_text("")
    other.write_text("ARMING_CHECK,1\nSERIAL0_BAUD,57\n")
    code, _, err = run(capsys, "params", "--check", str(empty))
    assert code == 1 and err.splitlines()[-1] == (
        f"{empty.as_posix()}: no BATT*_ parameter in this file (0 parameters read): nothing to check "
        "(--allow-empty accepts that)"
    )
    code, _, err = run(capsys, "params", "--check", str(other))
    assert code == 1 and "(2 parameters read)" in err
    code, _, err = run(capsys, "params", "--allow-empty", "--check", str(other))
    assert code == 0 and "0 errors, 0 warnings" in err


def test_failsafe_without_batt_parameters_or_samples(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    other, batt = tmp_path / "other.param", tmp_path / "batt.param"
    other.write_text("ARMING_CHECK,1\n")
    batt.write_text("BATT_CAPACITY,3300\nBATT_LOW_VOLT,10.5\n")
    stream, empty = tmp_path / "s.jsonl", tmp_path / "e.jsonl"
    stream.write_text('{"t": 0, "battery": {"voltage_v": 12.0, "remaining": 0.9}}\n')
    empty.write_text("")
    code, out, err = run(capsys, "failsafe", "--params", str(other), str(stream))
    assert (code, out) == (1, "") and err.strip() == (
        f"{other}: no BATT*_ parameter (1 parameters read): the failsafe would run on defaults "
        "alone (--allow-empty accepts that)"
    )
    code, out, err = run(capsys, "failsafe", "--allow-empty", "--params", str(other), str(stream))
    assert "no BATT*_ parameter" not in err and "vehicle" in err  # went on to the replay
    code, out, err = run(capsys, "failsafe", "--params", str(batt), str(empty))  # readable, no samples: exit 1
    assert code == 1 and "expected battery readings, found none" in err
    code, out, err = run(capsys, "failsafe", "--allow-empty", "--params", str(batt), str(empty))
    assert code == 0 and "no battery readings" in err


def test_generate_and_docs_out_onto_a_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    target = tmp_path / "pkg"
    target.write_text("not a folder")
    code, out, err = run(capsys, "generate", "--out", str(target))
    assert (code, out) == (
        2,
        "",
    ) and err.strip() == f"battgen: --out {target}: is a file; expected a folder for the package"
    code, out, err = run(capsys, "docs", "--out", str(target))
    assert (code, out) == (
        2,
        "",
    ) and err.strip() == f"battgen: --out {target}: is a file; expected a folder for the pages"
