"""Capture files written as the tools users record with write them: python-can's own log writers, by suffix."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def write_capture(path: Path, messages: list[Any]) -> Path:
    """``messages`` (python-can ``Message``s) into a capture file, the writer chosen by the file's suffix."""
    import can

    writer = can.Logger(str(path))
    try:
        for m in messages:
            writer.on_message_received(m)
    finally:
        writer.stop()
    return path
