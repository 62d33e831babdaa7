"""Binary message payloads as records, for the generated codecs to decode.

``hex``: one record a line, the payloads of a record with several messages (DroneCAN BatteryInfo
plus BatteryInfoAux) separated by spaces; blank lines are skipped. ``raw``: the whole input is one
payload. A record's data is the list of payloads, as bytes.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import IO

from .records import Item, Record, Unreadable

HEX_EXPECTED = "expected hexadecimal payloads"


def read_hex(stream: IO[bytes], name: str) -> Iterator[Item]:
    """One record per non-blank line of hexadecimal payloads, read lazily; a line that is not
    hexadecimal is an Unreadable item."""
    index = 0
    for number, raw in enumerate(stream, start=1):
        text = raw.decode("utf-8", "replace").strip()  # not hexadecimal either way when not ASCII
        if not text:
            continue
        try:
            payloads = [bytes.fromhex(part) for part in text.split()]
        except ValueError:
            yield Unreadable(name, number, HEX_EXPECTED)
            continue
        yield Record(index, number, payloads, name)
        index += 1


def read_raw(stream: IO[bytes], name: str) -> Iterator[Item]:
    """The whole stream as one record holding one payload."""
    yield Record(0, 1, [stream.read()], name)
