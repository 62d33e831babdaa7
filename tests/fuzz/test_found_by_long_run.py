"""Defects the long fuzz run (long_run.py --inputs) found, each rebuilt here from the format as a synthetic file
(the failing inputs were mutations of seeds and upstream files, which are not kept)."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from codegen.apps.battery.view import read_view
from codegen.inputs.devicetree.model import DevicetreeError
from codegen.inputs.devicetree.reading import read_nodes
from codegen.inputs.records import InputError

SEEDS = Path(__file__).resolve().parent / "seeds"


def test_a_ulog_start_time_beyond_int64_is_one_located_error(tmp_path: Path) -> None:
    """The header's uint64 start time of 2^64 - 1 raised OverflowError where the times became int64."""
    data = bytearray((SEEDS / "flight.ulg").read_bytes())
    data[8:16] = struct.pack("<Q", 2**64 - 1)  # after the 7-byte magic and the version byte
    path = tmp_path / "far.ulg"
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match="a start time of 18446744073709551615"):
        list(read_view(path))


def test_a_dts_number_of_thousands_of_digits_is_one_located_error(tmp_path: Path) -> None:
    """A decimal cell of 4,407 digits raised Python's ValueError on converting more than 4,300 digits."""
    path = tmp_path / "long.dts"
    path.write_text("/dts-v1/;\n/ {\n\tx = <" + "9" * 4400 + ">;\n};\n", encoding="ascii")
    with pytest.raises(DevicetreeError, match="a number of 4400 digits: expected at most 256") as err:
        read_nodes(path)
    assert err.value.line == 3
