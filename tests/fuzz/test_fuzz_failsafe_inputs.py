"""Fuzzing the failsafe's inputs: parameter files and DataFlash logs of any bytes are read or refused
with a located error (ParameterFileError / InputError), never another exception."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from budget import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from codegen.inputs.dataflash import log as dataflash
from codegen.inputs.parameters import files as parameter_files
from codegen.inputs.records import InputError

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs"))
from dataflash_writer import battery_log

LINES = st.sampled_from(
    [
        "BATT_LOW_VOLT,10.5",
        "BATT2_FS_LOW_ACT 2",
        "1\t1\tBATT_CAPACITY\t3300\t6",
        "# c",
        "",
        "BATT_X,0x1F",
        "\t",
        "a,b,c",
    ]
)


@fuzz_settings(150)
@given(st.lists(LINES | st.text(max_size=40), max_size=30), st.sampled_from(["\n", "\r\n"]))
def test_parameter_text_is_read_or_refused_with_a_line(lines: list[str], end: str) -> None:
    try:
        entries = parameter_files.parse_text(end.join(lines), "f.param")
    except parameter_files.ParameterFileError as exc:
        assert 0 <= exc.line <= len(lines) + 1
        return
    assert all(parameter_files.NAME.fullmatch(e.name) for e in entries)
    parameter_files.repeats(entries)


@fuzz_settings(60)
@given(st.binary(max_size=600), st.integers(0, 400))
def test_dataflash_bytes_never_crash(noise: bytes, cut: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        good = battery_log(Path(tmp) / "g.bin", {"BATT_LOW_VOLT": 10.5}, [(1.0, 0, 12.0, 1.0, 5.0)], [(0.5, True)])
        data = good.read_bytes()
        for variant, body in (("spliced", data[:cut] + noise + data[cut:]), ("raw", noise), ("cut", data[:cut])):
            path = Path(tmp) / f"{variant}.bin"
            path.write_bytes(body)
            try:
                log = dataflash.open_log(path)
                list(dataflash.flight_records(log))
                dataflash.log_parameters(log)
            except InputError as exc:
                assert exc.file == path.as_posix()
