"""The limits a schema file must keep, checked where its text enters battgen (README "Limits").

Schema files come from anywhere, so everything that could make a frontend, pymavlink's parser or the
generated code grow without bound is refused here, before any parsing, with a SchemaError at a line:

- the size of one schema file (the bundled and upstream ones are far below it);
- the length of a run of decimal digits: Python refuses to turn more than 4,300 digits into an int and
  takes quadratic time below that; no schema needs more than a few dozen digits (a 64-bit value in
  binary is 64);
- the nesting depth and the text of one element of XML (:mod:`.xml` applies them while it streams):
  pymavlink concatenates an element's text piece by piece and recurses through nested elements.

Array capacities are a limit of the IR (``ir.fieldtypes.MAX_ARRAY_CAPACITY``), checked by the frontends.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import SchemaError
from .files import read_text

MAX_SCHEMA_BYTES = 32 * 1024 * 1024  # ArduPilot's apm.pdef.xml, the largest upstream schema file, is ~3 MB
MAX_NUMBER_DIGITS = 256
MAX_XML_DEPTH = 32  # MAVLink dialects nest 5 deep, apm.pdef.xml 6
MAX_XML_TEXT = 64 * 1024  # characters of text in one element; pymavlink's longest description has 1,991

_LONG_DIGITS = re.compile(f"[0-9]{{{MAX_NUMBER_DIGITS + 1},}}")


def check_schema_size(size: int, display: str) -> None:
    """Refuse a schema file larger than MAX_SCHEMA_BYTES (SchemaError at line 0)."""
    if size > MAX_SCHEMA_BYTES:
        raise SchemaError(
            display, 0, f"expected a schema file of at most {MAX_SCHEMA_BYTES} bytes (docs/limits.md), got {size}"
        )


def check_schema_text(text: str, display: str) -> str:
    """``text`` when it keeps the limits on size and number length; SchemaError at the line otherwise."""
    check_schema_size(len(text), display)
    match = _LONG_DIGITS.search(text)
    if match is not None:
        line = text.count("\n", 0, match.start()) + 1
        raise SchemaError(
            display,
            line,
            f"expected a number of at most {MAX_NUMBER_DIGITS} digits (docs/limits.md), "
            f"got one of {len(match.group())} digits",
        )
    return text


def read_schema_text(path: Path, display: str) -> str:
    """A schema file's text: UTF-8 (:func:`.files.read_text`) within the limits above, its size checked
    before it is read."""
    try:
        check_schema_size(path.stat().st_size, display)
    except OSError:
        pass  # read_text reports what cannot be read
    return check_schema_text(read_text(path, display), display)
