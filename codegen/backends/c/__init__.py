"""C99 backend: one header per message of the IR (struct, constants, identities, prototypes) and one
source file per format (MAVLink, uORB, DroneCAN) with the codecs and validators of its messages; no
heap, no C library: the codecs, the validators (field checks, then the cross-field rules) and the
converters generated from the mappings (``convert.c``).
Output is formatted by ``clang-format`` (Debian's) with the style in :data:`STYLE`, so it is
deterministic and passes the formatter check.
"""

from __future__ import annotations

from .render import render_library
from .writer import generate_c

__all__ = ["generate_c", "render_library"]
