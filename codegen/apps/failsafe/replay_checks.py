"""A replay checked against what the firmware logged, for both firmwares: the changes of a level (or a count of
events) on each side, and whether they agree (same values, each within one sample of the log's), or why the log
cannot decide."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..battery.columns import NDArray


@dataclass(frozen=True)
class Change:
    """A level (or mode) taken at time ``t`` (the first sample's value counts as a change from 0)."""

    t: float
    value: int


@dataclass
class Check:
    """One comparison of the replay with the log."""

    what: str
    logged: list[Change]
    replayed: list[Change]
    problems: list[str] = field(default_factory=list)
    undecided: str = ""  # why the log cannot decide (then nothing was compared)

    @property
    def ok(self) -> bool:
        return not self.undecided and not self.problems

    def verdict(self) -> str:
        """The check in words, as ``battgen failsafe`` prints it."""
        if self.undecided:
            return f"undecided: {self.undecided}"
        if self.problems:
            return "DIFFERS: " + "; ".join(self.problems)
        return f"reproduced ({len(self.logged)} logged changes)"


def changes(t: NDArray, values: NDArray, *, skip: int | None = None) -> list[Change]:
    """The changes of a column (a first value other than 0 counts as one); ``skip``: a value that is unknown."""
    out: list[Change] = []
    last = 0
    for tk, vk in zip(t.tolist(), values.tolist(), strict=True):
        if skip is not None and vk == skip:
            continue
        if vk != last:
            out.append(Change(tk, int(vk)))
            last = vk
    return out


def interval(times: NDArray, t: float) -> float:
    """The larger of the sample intervals of ``times`` around ``t``."""
    k = int(np.searchsorted(times, t))
    gaps = [times[i] - times[i - 1] for i in (k, k + 1) if 0 < i < len(times)]
    return float(max(gaps, default=0.0))


def within_one_sample(logged: list[Change], replayed: list[Change], times: list[NDArray]) -> list[str]:
    """Problems: the values differ, or a replayed change is further from its logged one than one sample of any of
    ``times`` (the intervals around the logged change)."""
    if [c.value for c in logged] != [c.value for c in replayed]:
        return [f"levels {[c.value for c in logged]} logged, {[c.value for c in replayed]} replayed"]
    problems = []
    for got, want in zip(replayed, logged, strict=True):
        slack = max(interval(ts, want.t) for ts in times)
        if abs(got.t - want.t) > slack + 1e-6:
            problems.append(f"level {want.value} at {got.t:.3f}s, logged at {want.t:.3f}s (one sample: {slack:.3f}s)")
    return problems
