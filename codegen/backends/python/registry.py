"""The extensions every generated package gets, in the order their code appears in a class."""

from __future__ import annotations

from . import codec_dronecan, codec_mavlink, codec_uorb, validators
from .converters import EXTENSION as CONVERTERS
from .extensions import Extension

EXTENSIONS: tuple[Extension, ...] = (
    codec_dronecan.EXTENSION,
    codec_uorb.EXTENSION,
    codec_mavlink.EXTENSION,
    validators.EXTENSION,
    CONVERTERS,
)
