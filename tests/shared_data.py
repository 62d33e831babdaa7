"""Where the upstream files and real logs the tests read live: ``../shared`` beside the repository.

Nothing upstream is committed (definitions, logs and captures belong to their authors); CI has ``../shared``
beside the clone, and a user's checkout may point elsewhere with ``BATTGEN_SHARED``. Outside CI a test whose
files are missing skips; under CI (``CI`` set) it fails, so a missing corpus can never turn into a green run
that tested nothing.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SHARED = Path(os.environ.get("BATTGEN_SHARED") or ROOT.parent / "shared")
UPSTREAM = SHARED / "corpus" / "upstream"  # definition corpora: px4_msgs, mavlink, linux_batteries, ...
REAL_LOGS = SHARED / "data" / "ulog"  # the two real PX4 logs


def shared(*parts: str) -> Path:
    """A path under the shared folder (it may not exist: see :func:`require`)."""
    return SHARED.joinpath(*parts)


def missing(what: str) -> None:
    """A test's shared files are not here: skip outside CI, fail under it."""
    message = f"{what} not present under {SHARED} (set BATTGEN_SHARED to the shared folder)"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def require(path: Path, what: str | None = None) -> Path:
    """``path`` if it exists, else :func:`missing`."""
    if not path.exists():
        missing(what or path.as_posix())
    return path


def real_logs(pattern: str = "*.ulg") -> list[Path]:
    """The real PX4 logs of ``shared/data/ulog``, for a test's parameters: none outside CI when absent (the
    tests of them then do not run), a collection error under CI."""
    logs = sorted(REAL_LOGS.glob(pattern))
    if not logs and os.environ.get("CI"):
        pytest.fail(f"no real PX4 logs ({pattern}) under {REAL_LOGS}", pytrace=False)
    return logs
