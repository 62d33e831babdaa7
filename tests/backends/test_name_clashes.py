"""Definitions whose generated names clash make ``battgen generate`` exit 2 naming both source files, before
anything is written (once the last silently won and the others vanished)."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.backends.python import render_package
from codegen.cli.main import main
from codegen.errors import ErrorList, SchemaError
from codegen.frontends.loader import load

MSG = "uint64 timestamp\nfloat32 voltage_v\n"


def _generate(capsys: pytest.CaptureFixture[str], schemas: Path, out: Path) -> tuple[int, list[str]]:
    code = main(["generate", str(schemas), "--out", str(out), "--lang", "python"])
    return code, capsys.readouterr().err.splitlines()


def test_uorb_names_that_differ_only_by_case(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    schemas = tmp_path / "uorb"
    schemas.mkdir()
    for name in ("Battery", "battery", "BATTERY"):
        (schemas / f"{name}.msg").write_text(MSG, encoding="utf-8")
    out = tmp_path / "pkg"
    code, err = _generate(capsys, schemas, out)
    assert code == 2 and not out.exists()  # nothing written
    assert err[-1] == "battgen: 2 errors"
    for line in err[:-1]:  # each names its own file and the one it clashes with
        assert "generates the class uorb.Battery, as uorb.BATTERY (" in line and "BATTERY.msg:1)" in line
    assert sorted(line.split(":", 2)[1] for line in err[:-1]) == [" Battery.msg", " battery.msg"]


def test_mavlink_names_that_differ_only_by_underscores(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    schemas = tmp_path / "mavlink"
    schemas.mkdir()
    message = (
        '<message id="{id}" name="{name}"><description>x</description>'
        '<field type="uint8_t" name="a">a</field></message>'
    )
    (schemas / "clash.xml").write_text(
        "<mavlink><messages>\n"
        + message.format(id=180, name="FOO_BAR")
        + "\n"
        + message.format(id=181, name="FOO__BAR")
        + "\n</messages></mavlink>\n",
        encoding="utf-8",
    )
    code, err = _generate(capsys, schemas / "clash.xml", tmp_path / "pkg")
    assert code == 2 and len(err) == 1, err
    assert "clash.xml:3: expected a name of its own: mavlink.FOO__BAR generates the class mavlink.FooBar" in err[0]
    assert "as mavlink.FOO_BAR (" in err[0] and "clash.xml:2)" in err[0]


def test_the_library_refuses_too_and_the_bundled_schemas_have_no_clash(tmp_path: Path) -> None:
    (tmp_path / "A.msg").write_text(MSG, encoding="utf-8")
    (tmp_path / "a.msg").write_text(MSG, encoding="utf-8")
    with pytest.raises(SchemaError, match=r"generates the class uorb\.A"):
        render_package(load([tmp_path]))
    try:
        render_package(load([Path(__file__).resolve().parents[2] / "schemas"]))
    except (SchemaError, ErrorList) as exc:  # pragma: no cover - the failure message is the point
        pytest.fail(f"the bundled schemas clash: {exc}")
