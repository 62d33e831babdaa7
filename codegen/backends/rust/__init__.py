"""Rust backend: a ``no_std`` Cargo crate of the IR's DroneCAN, MAVLink and uORB messages (structs,
``Option`` accessors for sentinels, enums, constants, MAVLink 2, uORB and DroneCAN codecs, validators).

Templates render what varies per schema; hand-written support modules (``support/*.rs``: checksum,
byte and bit access, float16, the problem list, the MAVLink frame) are copied verbatim. rustfmt formats every ``.rs``
file, so the crate passes ``cargo fmt --check`` as committed.
"""

from __future__ import annotations

from .render import render_crate
from .writer import generate_rust

__all__ = ["generate_rust", "render_crate"]
