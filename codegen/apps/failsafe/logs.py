"""Real flights as failsafe samples, from the battery view (:mod:`codegen.apps.battery.view`) that ``export`` and
``report`` read too: the same records, the same clock, the same "armed" and the same concepts.

One sample per battery record of any log kind the view reads (PX4 ULog, MAVLink tlog, ArduPilot DataFlash, CAN
captures), in time order across the log's batteries (a tie: the lower battery first), each with:

- ``t``: the view's seconds since the log's start;
- the battery: ArduPilot's 1-based number, the view's battery + 1;
- the reading: the concepts ``pack_voltage`` (V), ``current`` (A) and ``discharged`` (C, as mAh), unknown where the
  IR says so (a field's sentinel; a negative current stays, as a charging battery). A value that came from a
  float32 field is taken as its shortest decimal, as a person reads the log (16.2 V, not 16.200000762939453), so
  that it compares with a parameter as the firmware's float32 comparison does;
- ``armed``: the view's arming state as of the record; before the log's first arming state the vehicle is
  disarmed, and a log with no arming state at all (a CAN capture) is taken as armed throughout
  (:data:`NO_ARMING_NOTE`).

:class:`SampleTable` keeps what a replay needs of each chunk (six numbers a record) so that ``export --failsafe``
replays a log from the chunks it has already read, without reading the file again.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from ...inputs.dataflash import log as dataflash
from ..battery.columns import NDArray
from ..battery.context import LogContext
from ..battery.view import Chunk, read_view
from .legacy_parameters import with_current_names
from .reading import BatteryReading, Sample

COULOMB_PER_MAH = 3.6
NO_ARMING_NOTE = "taken as armed throughout (this input has no arming state)"


class SampleTable:
    """The failsafe's view of a log's chunks, gathered as columns; :meth:`samples` gives them in time order."""

    def __init__(self) -> None:
        self._parts: list[tuple[NDArray, ...]] = []
        self.has_arming = False
        self.messages: list[str] = []
        self._order: tuple[NDArray, ...] | None = None  # the columns in time order, once asked for
        self.context: LogContext | None = None  # what the log says about itself (its first chunk's)

    @property
    def empty(self) -> bool:
        """No battery record at all (a readable log may hold none)."""
        return not self._parts

    def add(self, chunk: Chunk) -> None:
        if self.context is None:
            self.context = chunk.batch.context
        if not chunk.n:
            return
        self._order = None
        batch = chunk.batch
        if batch.armed is not None:
            self.has_arming = True
        armed = np.full(chunk.n, np.nan) if batch.armed is None else np.asarray(batch.armed, np.float64)
        self._parts.append(
            (
                np.asarray(batch.t, np.float64),
                chunk.battery.astype(np.int64),
                _as_logged(chunk.number("pack_voltage")),
                _as_logged(chunk.number("current")),
                _as_logged(chunk.number("discharged") / COULOMB_PER_MAH),
                armed,
                np.arange(chunk.n, dtype=np.int64),
                np.full(chunk.n, len(self.messages), np.int64),
            )
        )
        self.messages.append(batch.message)

    def _sorted(self) -> tuple[NDArray, ...]:
        t, battery, volts, amps, mah, armed, row, part = (np.concatenate(c) for c in zip(*self._parts, strict=True))
        order = np.lexsort((battery, t))  # by time, then battery; a record without a time sorts last
        if self.has_arming:
            armed = np.where(np.isnan(armed), 0.0, armed)  # disarmed before the log's first arming state
        else:
            armed = np.ones_like(armed)
        return t[order], battery[order], volts[order], amps[order], mah[order], armed[order], row[order], part[order]

    def sorted_columns(self) -> tuple[NDArray, ...]:
        """The samples as columns in time order: t, battery (0-based), V, A, mAh, armed (1.0 / 0.0) and each one's
        position for :meth:`sample_at`; records without a time left out."""
        if not self._parts:
            empty = np.zeros(0)
            return empty, empty.astype(np.int64), empty, empty, empty, empty, empty.astype(np.int64)
        if self._order is None:
            self._order = self._sorted()
        t, battery, volts, amps, mah, armed = self._order[:6]
        keep = np.flatnonzero(~np.isnan(t))
        return t[keep], battery[keep], volts[keep], amps[keep], mah[keep], armed[keep], keep

    def sample_at(self, k: int) -> Sample:
        """The sample at position ``k`` of the time order, as :meth:`samples` gives it."""
        if self._order is None:
            self._order = self._sorted()
        tk, bk, vk, ik, mk, ak, rk, pk = (c[k].item() for c in self._order)
        place = f"{self.messages[int(pk)]} record {int(rk)} of battery {bk}"
        reading = BatteryReading(_opt(vk), _opt(ik), _opt(mk))
        return Sample(k + 1, tk, ak == 1.0, reading, None, None, {}, bk + 1, place)

    def samples(self) -> Iterator[Sample]:
        if not self._parts:
            return
        t, battery, volts, amps, mah, armed, row, part = self._sorted()
        columns = (t, battery, volts, amps, mah, armed)
        where = (row, part)
        for k, (tk, bk, vk, ik, mk, ak) in enumerate(zip(*(c.tolist() for c in columns), strict=True)):
            if tk != tk:  # NaN: a record the log gives no time for cannot be replayed
                continue
            place = f"{self.messages[int(where[1][k])]} record {int(where[0][k])} of battery {bk}"
            reading = BatteryReading(_opt(vk), _opt(ik), _opt(mk))
            yield Sample(k + 1, tk, ak == 1.0, reading, None, None, {}, bk + 1, place)


def _opt(value: float) -> float | None:
    return None if value != value else value


def _as_logged(values: NDArray) -> NDArray:
    """Values that are exactly a float32 (read from a float32 field) as their shortest decimal."""
    out = np.array(values, np.float64)
    single = ~np.isnan(out) & (out.astype(np.float32).astype(np.float64) == out) & (out != np.round(out))
    if single.any():
        # a log repeats its readings: each distinct value converted once, then spread back
        distinct, back = np.unique(out[single], return_inverse=True)
        out[single] = np.array([dataflash.shortest_float32(x) for x in distinct.tolist()], np.float64)[back]
    return out


def log_samples(path: Path, name: str | None = None, subjects: Sequence[str] = ()) -> SampleTable:
    """Every battery record of a log as samples (an InputError, or another BattgenError, if unreadable);
    ``subjects``: the ``--cyphal-subject`` pairs a CAN capture's Cyphal subjects are read with."""
    table = SampleTable()
    for chunk in read_view(path, name, subjects=subjects):
        table.add(chunk)
    return table


def own_parameters(table: SampleTable) -> dict[str, float] | None:
    """The ArduPilot parameters a log recorded itself, from the context its read stated (a DataFlash log's PARM
    records, a tlog's PARAM_VALUE frames: a value set again takes its last), older names mapped to today's; None for
    a log of another firmware or one that records none (a PX4 log's parameters are PX4's: no BATT_* for ArduPilot's
    failsafe)."""
    context = table.context
    if context is None or context.autopilot != "ardupilot":
        return None
    if not context.parameters and context.kind != "dataflash":
        return None  # a tlog without PARAM_VALUE frames
    return with_current_names(dict(context.parameters))
