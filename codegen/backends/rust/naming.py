"""Rust names for schema names: modules and fields in snake_case, types and variants in CamelCase,
keywords avoided. Rust's lints (non_camel_case_types, non_snake_case) decide the spellings."""

from __future__ import annotations

import re

# strict and reserved keywords of Rust 2021; a field so named gets a trailing underscore
KEYWORDS = frozenset(
    "as break const continue crate else enum extern false fn for if impl in let loop match mod move mut pub ref "
    "return self Self static struct super trait true type unsafe use where while async await dyn abstract become "
    "box do final macro override priv typeof unsized virtual yield try union".split()
)


def _words(name: str) -> list[str]:
    """``BATTERY_STATUS_V2`` / ``BatteryStatusV0`` / ``voltage-min`` -> their words."""
    spaced = re.sub(r"[^0-9A-Za-z]+", " ", name)
    spaced = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", " ", spaced)
    return spaced.split()


def snake(name: str) -> str:
    """A module or field identifier."""
    out = "_".join(w.lower() for w in _words(name)) or "_"
    if out[0].isdigit():
        out = "_" + out
    return out + "_" if out in KEYWORDS else out


def field_ident(name: str) -> str:
    """A struct field: the schema's own spelling when it is already snake_case (``voltage_cell_v``)."""
    if re.fullmatch(r"[a-z_][a-z0-9_]*", name):
        return name + "_" if name in KEYWORDS else name
    return snake(name)


def camel(name: str) -> str:
    """A type or variant name (``MAV_BATTERY_CHARGE_STATE`` -> ``MavBatteryChargeState``)."""
    out = "".join(w[:1].upper() + w[1:].lower() for w in _words(name)) or "X"
    return "N" + out if out[0].isdigit() else out


def upper(name: str) -> str:
    """A constant (``MAX_INSTANCES``)."""
    out = "_".join(w.upper() for w in _words(name)) or "_"
    return "N" + out if out[0].isdigit() else out
