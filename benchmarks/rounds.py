"""What every benchmark times with: fresh processes' CPU and wall seconds, sides taking turns over rounds, min and
median, and the machine's state (cores, load average) to print beside the figures."""

from __future__ import annotations

import os
import statistics
import subprocess
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class Timing:
    """One side's seconds over the rounds."""

    wall: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)

    @property
    def median(self) -> float:
        """The median CPU seconds (what a shared machine's load disturbs least)."""
        return statistics.median(self.cpu)

    @property
    def best(self) -> float:
        return min(self.cpu)

    def text(self) -> str:
        wall = statistics.median(self.wall)
        return f"cpu min {self.best:7.3f} s  median {self.median:7.3f} s  (wall median {wall:.3f} s)"


def child(
    argv: list[str], env: Mapping[str, str] | None = None, ok: tuple[int, ...] = (0,)
) -> tuple[float, float, str]:
    """Run ``argv`` in a fresh process: its wall and CPU seconds and its stdout."""
    if env is None:  # bytecode written and read, as an installed tool's (this machine may turn that off)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    before, start = os.times(), time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    wall, after = time.perf_counter() - start, os.times()
    if done.returncode not in ok:
        raise RuntimeError(f"{' '.join(argv)}: exit {done.returncode}: {done.stderr.strip()[-400:]}")
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, cpu, done.stdout


def in_process(fn: Callable[[], Any]) -> tuple[float, float, Any]:
    """Call ``fn`` here: its wall and CPU seconds and its result."""
    start, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - start, time.process_time() - cpu, out


def interleaved(
    sides: Mapping[str, Callable[[], tuple[float, float, Any]]], rounds: int
) -> tuple[dict[str, Timing], dict[str, Any]]:
    """Each side once per round, in turn (a load that comes and goes falls on both); each side's last output."""
    times = {name: Timing() for name in sides}
    outputs: dict[str, Any] = {}
    for _ in range(rounds):
        for name, run in sides.items():
            wall, cpu, out = run()
            times[name].wall.append(wall)
            times[name].cpu.append(cpu)
            outputs[name] = out
    return times, outputs


def machine() -> str:
    """Cores and load average, to print at a run's start and end."""
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"{os.cpu_count()} cores, load average {load}"
