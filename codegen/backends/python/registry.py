"""The extensions every generated package gets, in the order their code appears in a class."""

from __future__ import annotations

from . import validators
from .codecs import cyphal, dronecan, mavlink, uorb
from .converters import EXTENSION as CONVERTERS
from .extensions import Extension

EXTENSIONS: tuple[Extension, ...] = (
    dronecan.EXTENSION,
    cyphal.EXTENSION,
    uorb.EXTENSION,
    mavlink.EXTENSION,
    validators.EXTENSION,
    CONVERTERS,
)
