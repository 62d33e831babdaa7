"""A schema folder with errors reports every error of every file in one run, as a compiler does:
several lines of one file, several files of one format, several formats; exit 2 from the CLI."""

from __future__ import annotations

from pathlib import Path

import pytest

from codegen.cli.main import main
from codegen.errors import ErrorList, LocatedError
from codegen.frontends import uorb
from codegen.frontends.loader import load

HEAD = "uint64 timestamp # [us] Time since system start\n"


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


def located(error: ErrorList) -> list[tuple[str, int]]:
    assert all(isinstance(e, LocatedError) for e in error.errors)
    return [(e.file, e.line) for e in error.errors if isinstance(e, LocatedError)]


@pytest.fixture
def broken_uorb(tmp_path: Path) -> Path:
    folder = tmp_path / "uorb"
    write(folder / "Alpha.msg", HEAD + "float32[] cells\nuint8 Bad\nfloat32 y # [@range 3, 1]\nuint8 fine\n")
    write(folder / "Beta.msg", HEAD + "uint8 X = 300\n")
    write(folder / "Gamma.msg", HEAD + "Beta beta\n")  # nests a broken file: no second report
    write(folder / "Delta.msg", HEAD + "uint8 ok\n")
    return folder


def test_every_bad_line_of_every_file(broken_uorb: Path) -> None:
    with pytest.raises(ErrorList) as info:
        uorb.parse_dir(broken_uorb)
    assert located(info.value) == [("Alpha.msg", 2), ("Alpha.msg", 3), ("Alpha.msg", 4), ("Beta.msg", 2)]
    text = str(info.value).splitlines()
    assert text[0].startswith("Alpha.msg:2: expected a fixed array size") and text[-1] == "4 errors"


def test_a_single_file_reports_its_nested_files_errors(broken_uorb: Path) -> None:
    with pytest.raises(LocatedError) as info:  # one error: raised as itself
        uorb.parse_file(broken_uorb / "Gamma.msg", root=broken_uorb)
    assert (info.value.file, info.value.line) == ("Beta.msg", 2)


def test_every_format_folder_is_read(broken_uorb: Path, tmp_path: Path) -> None:
    write(tmp_path / "dronecan" / "ns" / "A.uavcan", "uint8 x\n???\n")
    write(tmp_path / "dronecan" / "ns" / "B.uavcan", "uint8 y\nfloat99 z\n")
    write(tmp_path / "devicetree" / "a.yaml", "a: [\n")
    write(tmp_path / "devicetree" / "b.yaml", "b: {\n")
    write(tmp_path / "mavlink" / "bad.xml", "<mavlink><messages>\n")
    write(tmp_path / "params" / "x.pdef.xml", "<paramfile>\n")
    write(tmp_path / "params" / "y.pdef.xml", "<paramfile><x>\n")
    with pytest.raises(ErrorList) as info:
        load([tmp_path])
    files = [file for file, _ in located(info.value)]
    assert files == ["Alpha.msg"] * 3 + ["Beta.msg", "ns/A.uavcan", "ns/B.uavcan", "a.yaml", "b.yaml", "bad.xml"] + [
        "x.pdef.xml",
        "y.pdef.xml",
    ]


def test_several_paths_are_all_read(broken_uorb: Path, tmp_path: Path) -> None:
    with pytest.raises(ErrorList) as info:
        load([broken_uorb / "Beta.msg", tmp_path / "missing", broken_uorb / "Delta.msg"])
    assert [str(e) for e in info.value.errors] == [
        f"{broken_uorb / 'Beta.msg'}:2: expected a value in 0..255 for uint8, got 300",
        f"{tmp_path / 'missing'}: no such file or folder",
    ]


def test_the_cli_prints_one_line_per_error_and_exits_2(broken_uorb: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ir", str(broken_uorb)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == "" and len(lines) == 5 and lines[-1] == "battgen: 4 errors"
    assert all(line.startswith(("battgen: Alpha.msg:", "battgen: Beta.msg:")) for line in lines[:-1])


def test_warnings_go_to_stderr_and_do_not_fail(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write(tmp_path / "Sample.msg", HEAD + "float32 a # [m/s^2] [FRD] Lateral acceleration\n")
    assert main(["ir", str(tmp_path)]) == 0  # a folder of .msg files, as PX4's msg/
    captured = capsys.readouterr()
    assert '"frame": "FRD"' in captured.out
    assert captured.err == (
        "battgen: Sample.msg:2: warning: read '[FRD]' as the frame '[@frame FRD]', not as a unit "
        "(PX4's doc linter reports an unknown unit)\n"
    )
