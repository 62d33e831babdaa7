"""The extensions every generated package gets, in the order their code appears in a class."""

from __future__ import annotations

from . import validators
from .codecs import dronecan as codec_dronecan
from .codecs import mavlink as codec_mavlink
from .codecs import uorb as codec_uorb
from .converters import EXTENSION as CONVERTERS
from .extensions import Extension

EXTENSIONS: tuple[Extension, ...] = (
    codec_dronecan.EXTENSION,
    codec_uorb.EXTENSION,
    codec_mavlink.EXTENSION,
    validators.EXTENSION,
    CONVERTERS,
)
