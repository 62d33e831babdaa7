"""C99 backend: one header per message of the IR (struct, enums, constants, size checks).

This first slice writes the data types only; the codecs (DroneCAN, MAVLink v2) come next.
Output is formatted by ``clang-format`` (Debian's) with the style in :data:`STYLE`, so it is
deterministic and passes the formatter check.
"""

from __future__ import annotations

from .render import render_library
from .writer import generate_c

__all__ = ["generate_c", "render_library"]
