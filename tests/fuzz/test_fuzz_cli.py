"""Fuzzing the commands a user runs on data files: ``battgen validate`` (text and JSON reports),
``convert``, ``params`` and ``failsafe`` (on the text kinds) on mutated and random files of every kind,
in-process through ``main(argv)`` with the output captured.

Every run ends with exit status 0, 1 or 2 (2 with a message), no traceback, no defect hidden by a
catch-all and no message line longer than a screen (tests/fuzz/targets.py ``command``).
"""

from __future__ import annotations

import pytest
from budget import fuzz_settings
from fuzz_inputs import inputs
from hypothesis import given
from targets import SUFFIX, TARGETS, seeds


@pytest.mark.parametrize("kind", sorted(SUFFIX))
def test_fuzz_commands(kind: str) -> None:
    target = TARGETS[f"cli-{kind}"]

    @fuzz_settings(ci=20)
    @given(inputs(kind, seeds(kind)))
    def run(data: bytes) -> None:
        target(data)

    run()
