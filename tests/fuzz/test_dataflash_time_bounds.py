"""DataFlash inputs the long fuzz run found mishandled. A record whose time cannot be a time (beyond 2^62 us) is
read as a record without one, never cast into the int64 clock columns, where numpy would wrap it to a garbage time
with only a RuntimeWarning (tests/fuzz/crashers/view-dataflash/time-beyond-int64.bin). A format of length 0 is
refused (format-of-length-0.bin), a GPS week beyond uint16 gives no clock."""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import pytest
from budget import CRASHERS
from test_fuzz_data_layer import view

from codegen.apps.battery.catalog import bundled_catalog
from codegen.apps.battery.view import read_view
from codegen.errors import BattgenError
from codegen.inputs.dataflash.log import MAX_TIME_US, _time_us


def test_times_beyond_the_clock_are_no_time() -> None:
    assert _time_us({"TimeUS": 2**64 - 1}) is None
    assert _time_us({"TimeUS": MAX_TIME_US}) is None
    assert _time_us({"TimeUS": MAX_TIME_US - 1}) == MAX_TIME_US - 1
    assert _time_us({"TimeMS": 2**62}) is None
    assert _time_us({"TimeMS": 1500}) == 1_500_000
    assert _time_us({"TimeUS": -5}) is None


def test_the_crasher_reads_without_a_wrapped_time() -> None:
    data = (CRASHERS / "view-dataflash" / "time-beyond-int64.bin").read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        view("dataflash", data)


def test_a_format_of_length_zero_is_refused_not_walked_for_ever() -> None:
    """pymavlink steps back over such a record's header and parses it again, for ever (a hang the long fuzz run's
    alarm found, which the reader's catch-all had hidden): the reader refuses the log, naming the record."""
    data = (CRASHERS / "view-dataflash" / "format-of-length-0.bin").read_bytes()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "flight.bin"
        path.write_bytes(data)
        with pytest.raises(BattgenError, match=r"flight\.bin: .*offset \d+ of a format with no length"):
            list(read_view(path, path.name, catalog=bundled_catalog()))


def test_a_gps_week_beyond_uint16_gives_no_clock() -> None:
    """A GPS record's week is a uint16 and its milliseconds lie within the week, as ArduPilot logs them: a damaged
    one gave a UTC offset beyond int64 and an OverflowError (gps-week-beyond-uint16.bin)."""
    from codegen.inputs.dataflash.log import DataflashMessage, _gps_clock

    def gps(week: int, ms: int) -> DataflashMessage:
        return DataflashMessage("GPS", 0, 0, 1_000_000, {"GWk": week, "GMS": ms})

    assert _gps_clock(gps(2300, 5000)) is not None
    assert _gps_clock(gps(0xFFFF, 604_799_999)) is not None
    assert _gps_clock(gps(0x10000, 5000)) is None
    assert _gps_clock(gps(2300, 604_800_000)) is None
    assert _gps_clock(gps(2**70, 5000)) is None
    data = (CRASHERS / "view-dataflash" / "gps-week-beyond-uint16.bin").read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        view("dataflash", data)
