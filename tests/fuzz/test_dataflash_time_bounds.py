"""A DataFlash record whose time cannot be a time (beyond 2^62 us) is read as a record without one, never cast
into the int64 clock columns, where numpy would wrap it to a garbage time with only a RuntimeWarning (found by the
long fuzz run: tests/fuzz/crashers/view-dataflash/time-beyond-int64.bin)."""

from __future__ import annotations

import warnings

from budget import CRASHERS
from test_fuzz_data_layer import view

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
