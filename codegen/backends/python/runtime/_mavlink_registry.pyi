"""The shape of ``_mavlink_registry``, the one per-schema module the MAVLink runtime imports.

battgen generates that module for each package (codecs/mavlink.py) beside the copied ``_mavlink.py``;
this stub lets the runtime type-check here. It is not copied.
"""

REGISTRY: dict[int, tuple[int, str, int, str]]  # msgid -> (CRC_EXTRA, class name, MAVLINK_MAX_LENGTH, MAVLink name)
MODULE: str  # the generated module holding the MAVLink classes, relative to the package
