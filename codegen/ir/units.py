"""One unit registry for every format.

Each format spells units its own way: uORB ``[V]``, DroneCAN comments ``# [Volt]``, devicetree
property suffixes ``-microvolt``, MAVLink ``units="mV"``. All of them resolve here to a canonical
:class:`~codegen.ir.Unit` whose scale (and offset, for temperatures) relates it to the SI base
unit of its quantity, so a converter derives every factor from the IR.
"""

from __future__ import annotations

import re

from .basics import Unit

_C_PER_AH = 3600.0  # coulombs in one ampere-hour
_J_PER_WH = 3600.0

# canonical symbol -> (quantity, base, scale, offset)
_CANONICAL: dict[str, tuple[str, str, float, float]] = {
    # electric potential
    "V": ("voltage", "V", 1.0, 0.0),
    "mV": ("voltage", "V", 1e-3, 0.0),
    "uV": ("voltage", "V", 1e-6, 0.0),
    "cV": ("voltage", "V", 1e-2, 0.0),
    # current
    "A": ("current", "A", 1.0, 0.0),
    "cA": ("current", "A", 1e-2, 0.0),
    "mA": ("current", "A", 1e-3, 0.0),
    "uA": ("current", "A", 1e-6, 0.0),
    "nA": ("current", "A", 1e-9, 0.0),
    "pA": ("current", "A", 1e-12, 0.0),
    # electric charge (base: coulomb)
    "C": ("charge", "C", 1.0, 0.0),
    "Ah": ("charge", "C", _C_PER_AH, 0.0),
    "mAh": ("charge", "C", _C_PER_AH * 1e-3, 0.0),
    "uAh": ("charge", "C", _C_PER_AH * 1e-6, 0.0),
    # energy (base: joule)
    "J": ("energy", "J", 1.0, 0.0),
    "hJ": ("energy", "J", 100.0, 0.0),
    "kJ": ("energy", "J", 1e3, 0.0),
    "Wh": ("energy", "J", _J_PER_WH, 0.0),
    "mWh": ("energy", "J", _J_PER_WH * 1e-3, 0.0),
    "uWh": ("energy", "J", _J_PER_WH * 1e-6, 0.0),
    # power
    "W": ("power", "W", 1.0, 0.0),
    "mW": ("power", "W", 1e-3, 0.0),
    "uW": ("power", "W", 1e-6, 0.0),
    # resistance
    "Ohm": ("resistance", "Ohm", 1.0, 0.0),
    "mOhm": ("resistance", "Ohm", 1e-3, 0.0),
    "uOhm": ("resistance", "Ohm", 1e-6, 0.0),
    # capacitance
    "F": ("capacitance", "F", 1.0, 0.0),
    "pF": ("capacitance", "F", 1e-12, 0.0),
    "fF": ("capacitance", "F", 1e-15, 0.0),
    # temperature (base: kelvin; offsets for the Celsius family)
    "K": ("temperature", "K", 1.0, 0.0),
    "degC": ("temperature", "K", 1.0, 273.15),
    "cdegC": ("temperature", "K", 1e-2, 273.15),
    "mdegC": ("temperature", "K", 1e-3, 273.15),
    # time
    "s": ("time", "s", 1.0, 0.0),
    "ds": ("time", "s", 1e-1, 0.0),
    "cs": ("time", "s", 1e-2, 0.0),
    "ms": ("time", "s", 1e-3, 0.0),
    "us": ("time", "s", 1e-6, 0.0),
    "ns": ("time", "s", 1e-9, 0.0),
    "ps": ("time", "s", 1e-12, 0.0),
    "min": ("time", "s", 60.0, 0.0),
    "h": ("time", "s", 3600.0, 0.0),
    # frequency
    "Hz": ("frequency", "Hz", 1.0, 0.0),
    "kHz": ("frequency", "Hz", 1e3, 0.0),
    "MHz": ("frequency", "Hz", 1e6, 0.0),
    "rpm": ("frequency", "Hz", 1.0 / 60.0, 0.0),
    # dimensionless ratios (base: fraction)
    "1": ("ratio", "1", 1.0, 0.0),
    "%": ("ratio", "1", 1e-2, 0.0),
    "d%": ("ratio", "1", 1e-3, 0.0),
    "c%": ("ratio", "1", 1e-4, 0.0),
    "bp": ("ratio", "1", 1e-4, 0.0),
    # length
    "m": ("length", "m", 1.0, 0.0),
    "dam": ("length", "m", 10.0, 0.0),
    "dm": ("length", "m", 1e-1, 0.0),
    "cm": ("length", "m", 1e-2, 0.0),
    "mm": ("length", "m", 1e-3, 0.0),
    "km": ("length", "m", 1e3, 0.0),
    # velocity
    "m/s": ("velocity", "m/s", 1.0, 0.0),
    "cm/s": ("velocity", "m/s", 1e-2, 0.0),
    "mm/s": ("velocity", "m/s", 1e-3, 0.0),
    "dm/s": ("velocity", "m/s", 1e-1, 0.0),
    # acceleration
    "m/s^2": ("acceleration", "m/s^2", 1.0, 0.0),
    # angle
    "rad": ("angle", "rad", 1.0, 0.0),
    "mrad": ("angle", "rad", 1e-3, 0.0),
    "deg": ("angle", "rad", 0.017453292519943295, 0.0),
    "cdeg": ("angle", "rad", 0.017453292519943295e-2, 0.0),
    "degE5": ("angle", "rad", 0.017453292519943295e-5, 0.0),
    "degE7": ("angle", "rad", 0.017453292519943295e-7, 0.0),
    # angular rate
    "rad/s": ("angular_rate", "rad/s", 1.0, 0.0),
    "mrad/s": ("angular_rate", "rad/s", 1e-3, 0.0),
    "deg/s": ("angular_rate", "rad/s", 0.017453292519943295, 0.0),
    "ddeg/s": ("angular_rate", "rad/s", 0.017453292519943295e-1, 0.0),
    # pressure
    "Pa": ("pressure", "Pa", 1.0, 0.0),
    "hPa": ("pressure", "Pa", 1e2, 0.0),
    "kPa": ("pressure", "Pa", 1e3, 0.0),
    # magnetic flux density
    "gauss": ("magnetic_field", "T", 1e-4, 0.0),
    "mgauss": ("magnetic_field", "T", 1e-7, 0.0),
    "T": ("magnetic_field", "T", 1.0, 0.0),
    # mass
    "kg": ("mass", "kg", 1.0, 0.0),
    "g": ("mass", "kg", 1e-3, 0.0),
    # information
    "bit": ("information", "B", 0.125, 0.0),
    "B": ("information", "B", 1.0, 0.0),
    "KiB": ("information", "B", 1024.0, 0.0),
    "MiB": ("information", "B", 1048576.0, 0.0),
    "bit/s": ("data_rate", "B/s", 0.125, 0.0),
    "kB/s": ("data_rate", "B/s", 1e3, 0.0),
    "KiB/s": ("data_rate", "B/s", 1024.0, 0.0),
    "MiB/s": ("data_rate", "B/s", 1048576.0, 0.0),
    "dB": ("level", "dB", 1.0, 0.0),
}

# spelling (case-sensitive first, then case-folded) -> canonical symbol
_ALIASES: dict[str, str] = {
    "volt": "V",
    "volts": "V",
    "millivolt": "mV",
    "microvolt": "uV",
    "centivolt": "cV",
    "µV": "uV",
    "ampere": "A",
    "amp": "A",
    "amps": "A",
    "amperes": "A",
    "centiamp": "cA",
    "milliamp": "mA",
    "microamp": "uA",
    "nanoamp": "nA",
    "picoamp": "pA",
    "µA": "uA",
    "coulomb": "C",
    "ampere hours": "Ah",
    "amp hours": "Ah",
    "microamp-hours": "uAh",
    "milliamp hours": "mAh",
    "mah": "mAh",
    "µAh": "uAh",
    "joule": "J",
    "kilogram": "kg",  # Cyphal's uavcan.si.unit.mass.Scalar
    "hectojoule": "hJ",
    "watt hours": "Wh",
    "watt hour": "Wh",
    "watt-hours": "Wh",
    "milliwatt hours": "mWh",
    "microwatt-hours": "uWh",
    "µWh": "uWh",
    "watt": "W",
    "watts": "W",
    "milliwatt": "mW",
    "microwatt": "uW",
    "ohm": "Ohm",
    "ohms": "Ohm",
    "Ω": "Ohm",
    "milliohm": "mOhm",
    "micro-ohms": "uOhm",
    "µOhm": "uOhm",
    "picofarads": "pF",
    "femtofarads": "fF",
    "kelvin": "K",
    "°C": "degC",
    "celsius": "degC",
    "deg c": "degC",
    "degree celsius": "degC",
    "centidegree celsius": "cdegC",
    "millicelsius": "mdegC",
    "°": "deg",
    "second": "s",
    "seconds": "s",
    "sec": "s",
    "decisecond": "ds",
    "millisecond": "ms",
    "microsecond": "us",
    "µs": "us",
    "usec": "us",
    "nanosecond": "ns",
    "picosecond": "ps",
    "minute": "min",
    "minutes": "min",
    "hour": "h",
    "hours": "h",
    "hr": "h",
    "hertz": "Hz",
    "mhz": "MHz",
    "khz": "kHz",
    "percent": "%",
    "basis points": "bp",
    "norm": "1",
    "-": "1",
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "millimeter": "mm",
    "m/s/s": "m/s^2",
    "m/s2": "m/s^2",
    "degrees": "deg",
    "degree": "deg",
    "pascal": "Pa",
    "bytes": "B",
    "byte": "B",
    "bits": "bit",
    "bits/s": "bit/s",
    "bps": "bit/s",
    "kBps": "kB/s",
    "decibel": "dB",
    "db": "dB",
}
_FOLDED_ALIASES = {k.casefold(): v for k, v in _ALIASES.items()}
_FOLDED_CANONICAL = {k.casefold(): k for k in _CANONICAL}


def canonical_symbol(text: str) -> str | None:
    """The registry's symbol for a unit as some schema spells it, or None when unknown."""
    spelled = re.sub(r"\s+", " ", text.strip())
    if spelled in _CANONICAL:
        return spelled
    if spelled in _ALIASES:
        return _ALIASES[spelled]
    folded = spelled.casefold()
    # Case-folding is only safe where it cannot confuse prefixes (mA vs MA): aliases are words.
    return _FOLDED_ALIASES.get(folded) or (_FOLDED_CANONICAL.get(folded) if len(folded) > 2 else None)


def lookup(text: str) -> Unit | None:
    """Resolve a unit spelling to a :class:`Unit`; None when the registry does not know it."""
    symbol = canonical_symbol(text)
    if symbol is None:
        return None
    return unit(symbol)


def unit(symbol: str) -> Unit:
    quantity, base, scale, offset = _CANONICAL[symbol]
    return Unit(symbol=symbol, quantity=quantity, base=base, scale=scale, offset=offset)


def opaque(text: str) -> Unit:
    """A unit the registry does not know: kept, with its own spelling as its quantity, never converted."""
    return Unit(symbol=text, quantity=f"unknown:{text}", base=text)


# devicetree property-name suffixes (dt-schema's property-units.yaml), longest first
DT_SUFFIX_UNITS: tuple[tuple[str, str], ...] = (
    ("-microamp-hours", "uAh"),
    ("-microwatt-hours", "uWh"),
    ("-millicelsius", "mdegC"),
    ("-micro-ohms", "uOhm"),
    ("-microvolt", "uV"),
    ("-microamp", "uA"),
    ("-nanoamp", "nA"),
    ("-picoamp", "pA"),
    ("-microwatt", "uW"),
    ("-milliwatt", "mW"),
    ("-picofarads", "pF"),
    ("-femtofarads", "fF"),
    ("-celsius", "degC"),
    ("-kelvin", "K"),
    ("-percent", "%"),
    ("-ohms", "Ohm"),
    ("-kBps", "kB/s"),
    ("-bits", "bit"),
    ("-bps", "bit/s"),
    ("-mhz", "MHz"),
    ("-hz", "Hz"),
    ("-sec", "s"),
    ("-ms", "ms"),
    ("-us", "us"),
    ("-ns", "ns"),
    ("-ps", "ps"),
    ("-mm", "mm"),
    ("-bp", "bp"),
    ("-db", "dB"),
)


def devicetree_suffix_unit(prop: str) -> Unit | None:
    for suffix, symbol in DT_SUFFIX_UNITS:
        if prop.endswith(suffix):
            return unit(symbol)
    return None
