"""The scale of a DataFlash battery field: from the log's own ``FMTU``/``MULT`` records where it
has them, else from ArduPilot's logging code for the log's format.

Logs from ArduPilot 3.6 on carry ``FMTU`` (units and multipliers per field), and their ``BAT``
``Volt``/``Curr`` are floats in V and A, ``CurrTot`` in mAh (``3.6 A.s`` in some, the same unit).
Older logs have no ``FMTU``; their ``CURR`` record (LogStructure.h, ``Log_Write_Current``) logs
``battery.voltage() * 100`` and ``battery.current_amps() * 100`` as int16 (hundredths of V and
A), ``board_voltage`` in mV and ``current_total_mah()`` as a float in mAh. The formats seen with
int16 ``Volt``/``Curr``: ``hIhhhf`` (3.0), ``IhIhhhf``, ``IhhhHf``, ``IhhhHfh`` (3.2-3.3),
``QhhhHfh``; from about 3.5 the record is ``Qfff...`` (floats, already V and A).
"""

from __future__ import annotations

from collections.abc import Sequence

INTEGER_CHARS = frozenset("bBhHiIqQ")
# ArduPilot's pre-FMTU CURR/CURR2 fields logged as integers, and the factor back to V / A.
LEGACY_INTEGER_SCALE = {"Volt": 0.01, "Curr": 0.01, "Volt2": 0.01}
LEGACY_TYPES = frozenset({"CURR", "CURR2"})


def field_scales(
    type_name: str,
    format_chars: str,
    columns: Sequence[str],
    has_units: bool,
) -> dict[str, float]:
    """{field: factor} turning the values pymavlink decodes into the unit the field's name means
    (V, A, mAh); pymavlink applies the format letters' own scale (``c`` = x0.01 and the like)."""
    out: dict[str, float] = {}
    for index, name in enumerate(columns):
        char = format_chars[index] if index < len(format_chars) else ""
        if has_units:  # FMTU-era battery fields are floats in the unit their name means
            out[name] = 1.0
        elif type_name in LEGACY_TYPES and char in INTEGER_CHARS and name in LEGACY_INTEGER_SCALE:
            out[name] = LEGACY_INTEGER_SCALE[name]
        else:
            out[name] = 1.0
    return out
