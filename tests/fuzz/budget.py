"""The fuzzing budget shared by every fuzzer in tests/fuzz/.

CI runs a short budget on every run (a minute or two for the whole suite); a nightly or local long run sets
``BATTGEN_FUZZ=long`` (and optionally ``BATTGEN_FUZZ_EXAMPLES=N``) to try many more inputs per target.
Inputs that once crashed live in ``tests/fuzz/crashers/<target>/`` and are replayed on every run.
"""

from __future__ import annotations

import os
from pathlib import Path

from hypothesis import HealthCheck, settings

CRASHERS = Path(__file__).resolve().parent / "crashers"
LONG = os.environ.get("BATTGEN_FUZZ", "") == "long"


def examples(ci: int = 150) -> int:
    """How many inputs one fuzzer tries: ``ci`` in the default run, far more in the long mode."""
    override = os.environ.get("BATTGEN_FUZZ_EXAMPLES")
    if override:
        return int(override)
    return ci * 400 if LONG else ci


def fuzz_settings(ci: int = 150) -> settings:
    """Hypothesis settings for one fuzzer: no deadline (shared machines), the budget above."""
    return settings(
        max_examples=examples(ci),
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
    )


def crashers(target: str) -> list[Path]:
    """The saved inputs of one target that once crashed, hung or blew up memory, sorted for a stable order."""
    folder = CRASHERS / target
    return sorted(p for p in folder.iterdir() if p.is_file()) if folder.is_dir() else []
