"""The source format each file kind holds (the text kinds hold any): apart from :mod:`.kinds`, which tells a file's
kind without importing the IR (a command that only reads samples, ``battgen failsafe`` on JSON Lines, needs no more)."""

from __future__ import annotations

from ...ir import SourceFormat

KIND_FORMATS: dict[str, SourceFormat] = {
    "dts": SourceFormat.DEVICETREE,
    "dtb": SourceFormat.DEVICETREE,
    "param": SourceFormat.PDEF,
    "ulog": SourceFormat.UORB,
    "tlog": SourceFormat.MAVLINK,
    "mavlink": SourceFormat.MAVLINK,
    "can": SourceFormat.DRONECAN,
}
