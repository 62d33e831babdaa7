"""Battery samples for the failsafe evaluator: a JSON Lines stream, any supported message format.

Each line is one sample::

    {"t": 12.5, "armed": true, "message": "uorb.BatteryStatus", "data": {"voltage_v": 10.4, ...},
     "distance_to_home_m": 120.0, "travelled_m": 800.0, "home_set": true, "position_fix": true}

``t`` (seconds) and ``armed`` are required. The battery is either ``message`` + ``data`` (a message
of any bundled format, by qualified or short name; ``message`` may be left to a stream-wide default)
or ``battery``: the state in SI units directly (``voltage_v``, ``current_a``, ``consumed_mah``,
``remaining_mah``, or the shared concept names ``pack_voltage``, ``current``, ``discharged`` [C]).
The other keys are optional. Blank lines and lines starting with ``#`` are skipped (the lines
are read by the shared JSON Lines reader, :func:`codegen.inputs.documents.read_jsonl`).

Message data becomes a battery state through the IR: the generated model reads it (defaults,
sentinels), then the converters (the generated package's ``convert``, to the shared concepts)
give the canonical battery state in SI; without them a small IR-driven field table does
(:func:`battery_state_from_ir`).
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import math
import mmap
import re
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, Protocol, cast

from ...errors import BattgenError, LocatedError
from ...inputs.parameters import files as parameter_files
from .evaluator import BatteryFailsafe, Event
from .reading import BatteryReading, reading_of
from .reading import Sample as Sample  # where the CLI, the report and the logs' replay import it from

# A plain stream of SI samples needs none of the schemas' machinery (the IR, the frontends, the generated models,
# the converters: a third of a second of imports): it is imported where a message first asks for it.
if TYPE_CHECKING:
    from ...inputs.model import GeneratedMessage, MessageClass
    from ...ir import Schema
    from ..battery.sources import FloatFields

# which field carries what, per message (units come from the IR metadata)
ROLES: dict[str, dict[str, str]] = {
    "uorb.BatteryStatus": {"voltage": "voltage_v", "current": "current_a", "consumed": "discharged_mah"},
    "uorb.BatteryStatusV0": {"voltage": "voltage_v", "current": "current_a", "consumed": "discharged_mah"},
    "mavlink.BATTERY_STATUS": {
        "cells": "voltages",
        "cells_ext": "voltages_ext",
        "current": "current_battery",
        "consumed": "current_consumed",
    },
    "dronecan.uavcan.equipment.power.BatteryInfo": {"voltage": "voltage", "current": "current"},
}
# which field gives which quantity of a reading, per message: a value validate refuses there is no reading
_UORB_READS = {
    "voltage_v": "voltage_v",
    "current_a": "current_a",
    "discharged_mah": "consumed_mah",
    "remaining": "remaining_mah",
    "capacity": "remaining_mah",
}
_READS: dict[str, dict[str, str]] = {
    "uorb.BatteryStatus": _UORB_READS,
    "uorb.BatteryStatusV0": _UORB_READS,
    "mavlink.BATTERY_STATUS": {
        "voltages": "voltage_v",
        "voltages_ext": "voltage_v",
        "current_battery": "current_a",
        "current_consumed": "consumed_mah",
        "battery_remaining": "remaining_mah",
    },
    "dronecan.uavcan.equipment.power.BatteryInfo": {
        "voltage": "voltage_v",
        "current": "current_a",
        "state_of_charge_pct": "remaining_mah",
        "full_charge_capacity_wh": "remaining_mah",
    },
}
_OPTIONAL = {"distance_to_home_m": float, "travelled_m": float, "home_set": bool, "position_fix": bool}


class StreamError(LocatedError):
    """A malformed input file, located by file and line."""


def _si(meta: Mapping[str, Any], value: Any) -> float | None:
    """A value in its field's unit -> the quantity's SI base; None for the invalid sentinel."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    invalid = meta.get("invalid")
    if invalid is not None and not meta.get("per_element") and value == invalid:
        return None
    return float(value) * float(meta.get("scale", 1.0)) + float(meta.get("offset", 0.0))


# the converters' endpoint for each battery message (generated/convert: to the shared concepts)
ENDPOINTS: dict[str, str] = {
    "uorb.BatteryStatus": "uorb",
    "uorb.BatteryStatusV0": "uorb_v0",
    "mavlink.BATTERY_STATUS": "mavlink",
    "dronecan.uavcan.equipment.power.BatteryInfo": "dronecan",
}


class _Converters(Protocol):
    """What the failsafe takes of a generated package's ``convert`` module. Not the conversion app's protocol:
    importing it would close a cycle (strict conversion judges records by validate's gate, and validate imports
    the failsafe's parameter checks)."""

    def converter(self, source: str, target: str) -> Callable[..., object]: ...


def _converters(model: GeneratedMessage) -> _Converters | None:
    """The converters of the generated package ``model``'s class belongs to, if it has them."""
    from ...inputs.model import package_name

    try:
        module: ModuleType = importlib.import_module(package_name(cast("MessageClass", type(model))) + ".convert")
    except ImportError:
        return None
    return cast("_Converters", module)


def battery_state(qualified_name: str, model: GeneratedMessage) -> BatteryReading:
    """The failsafe's battery state from a generated model instance of a bundled battery message:
    through the converters to the shared concepts (canonical SI state) when the package has them."""
    endpoint = ENDPOINTS.get(qualified_name)
    if endpoint is not None:
        convert = _converters(model)
        if convert is not None:
            return reading_of(convert.converter(endpoint, "concepts")(model))
    return battery_state_from_ir(qualified_name, model)


def battery_state_from_ir(qualified_name: str, model: GeneratedMessage) -> BatteryReading:
    """Fallback without converters: the fields that carry voltage, current and drawn charge, with
    their units' scales from the generated metadata."""
    roles = ROLES.get(qualified_name)
    if roles is None:
        raise BattgenError(f"{qualified_name} carries no battery voltage or current (known: {', '.join(ROLES)})")
    fields = dataclasses.fields(cast(Any, model))  # a generated message is a dataclass
    metas = {f.metadata["name"]: f.metadata for f in fields}
    by_name = {f.metadata["name"]: getattr(model, f.name) for f in fields}

    def get(role: str) -> float | None:
        name = roles.get(role)
        return None if name is None else _si(metas[name], by_name[name])

    volts = get("voltage")
    if "cells" in roles:  # MAVLink: cell voltages (cell 0 holds the pack when there is no per-cell data)
        total = 0.0
        for role, absent in (("cells", metas[roles["cells"]].get("invalid")), ("cells_ext", 0)):
            meta = metas[roles[role]]
            for v in by_name[roles[role]]:
                if v != absent:
                    total += v * float(meta.get("scale", 1.0))
        volts = total or None
    consumed = get("consumed")
    return BatteryReading(
        voltage_v=volts,
        current_a=get("current"),
        consumed_mah=None if consumed is None else consumed / 3.6,  # coulombs -> mAh
    )


class Reader:
    """Reads a stream, resolving message names against a schema and its generated package."""

    def __init__(
        self,
        schema: Schema | None,
        package: ModuleType | None,
        default_message: str | None = None,
        loader: Callable[[], tuple[Schema, ModuleType]] | None = None,
    ) -> None:
        self._schema = schema
        self._package = package
        self._loader = loader  # the schema and package, loaded when a message first asks for them
        self.default_message = default_message
        self._classes: dict[str, tuple[str, MessageClass, FloatFields]] = {}

    def _load(self) -> None:
        if self._schema is None or self._package is None:
            if self._loader is None:
                raise ValueError("a Reader needs a schema and package, or a loader of them")
            self._schema, self._package = self._loader()

    @property
    def schema(self) -> Schema:
        self._load()
        assert self._schema is not None
        return self._schema

    @property
    def package(self) -> ModuleType:
        self._load()
        assert self._package is not None
        return self._package

    def model(self, name: str, file: str, line: int) -> tuple[str, MessageClass, FloatFields]:
        """A message name's qualified name, generated class and float fields (resolved once per name)."""
        if name not in self._classes:
            from ..battery.sources import float_fields
            from ..schemas.messages import resolve_message
            from ..schemas.package import model_class

            try:
                msg = resolve_message(self.schema, name)
            except BattgenError as exc:
                raise StreamError(file, line, str(exc)) from None
            self._classes[name] = (msg.qualified_name, model_class(self.package, msg), float_fields(msg))
        return self._classes[name]

    def read(self, path: Path) -> Iterator[Sample]:
        from ...inputs.documents import read_jsonl
        from ...inputs.records import Record, Unreadable

        file = path.as_posix()
        for item in read_jsonl(path, file, comments=True):  # InputError when the file cannot be opened
            if isinstance(item, Unreadable):
                if item.reason:
                    message = f"expected one JSON object per line ({item.reason} at column {item.column})"
                    raise StreamError(file, item.line, message)
                raise StreamError(file, item.line, item.message)
            if not isinstance(item, Record):
                continue  # JSON Lines readers tell no notices
            if not isinstance(item.data, dict):
                raise StreamError(file, item.line, "expected a JSON object per line")
            yield self.sample(item.data, file, item.line)

    def sample(self, obj: Mapping[str, Any], file: str, line: int) -> Sample:
        """One sample from a line's JSON object."""

        def fail(message: str) -> StreamError:
            return StreamError(file, line, message)

        t = obj.get("t")
        if isinstance(t, bool) or not isinstance(t, int | float) or not math.isfinite(t):
            raise fail(f'expected "t": a number of seconds, got {t!r}')
        armed = obj.get("armed")
        if not isinstance(armed, bool):
            raise fail(f'expected "armed": true or false, got {armed!r}')
        extra: dict[str, Any] = {}
        for key, kind in _OPTIONAL.items():
            if obj.get(key) is not None:
                value = obj[key]
                ok = (
                    isinstance(value, bool)
                    if kind is bool
                    else isinstance(value, int | float) and not isinstance(value, bool)
                )
                if not ok:
                    raise fail(f'expected "{key}": {"true or false" if kind is bool else "a number"}, got {value!r}')
                extra[key] = value
        instance = obj.get("instance")
        if instance is not None and (
            isinstance(instance, bool) or not isinstance(instance, int) or not 1 <= instance <= 16
        ):
            raise fail(f'expected "instance": a battery number from 1 to 16, got {instance!r}')
        if "battery" in obj:
            if not isinstance(obj["battery"], dict):
                raise fail('expected "battery": an object of SI values')
            return Sample(line, float(t), armed, reading_of(obj["battery"]), None, None, extra, instance or 1)
        name = obj.get("message", self.default_message)
        if not isinstance(name, str):
            raise fail('expected "message" (a message name) with "data", "battery", or --message')
        data = obj.get("data")
        if not isinstance(data, dict):
            raise fail(f'expected "data": an object of {name} fields')
        qualified, cls, floats = self.model(name, file, line)
        from ..battery.sources import stored_data

        try:
            # as the fields store them: a float32 voltage of 5e-324 is 0.0, the unknown, as the export reads it
            model = cls.from_dict(stored_data(floats, data))
            battery = known_only(qualified, model, battery_state(qualified, model))
        except (ValueError, BattgenError) as exc:
            raise fail(f"expected {qualified} data: {exc}") from None
        return Sample(line, float(t), armed, battery, qualified, data, extra, instance or _instance_of(qualified, data))


def known_only(qualified_name: str, model: GeneratedMessage, reading: BatteryReading) -> BatteryReading:
    """The reading without the quantities whose field holds a value validate refuses (:mod:`..schemas.fits`: one
    meaning of "fits"): a voltage beyond float32, a MAVLink current beyond int16, a NaN where the schema's unknown
    is another value is no measurement, and the failsafe reads it as unknown, as it reads the field's sentinel
    (never as a level to fire on)."""
    reads = _READS.get(qualified_name)
    check = getattr(model, "validate", None)
    if reads is None or not callable(check):
        return reading
    from ..schemas.fits import errors  # only a stream of messages validates

    found = check()
    if not found:
        return reading
    unknown = {reads[f] for v in errors(found) if (f := str(v.path).split("[", 1)[0].split(".", 1)[0]) in reads}
    return dataclasses.replace(reading, **dict.fromkeys(unknown)) if unknown else reading


def open_reader(schema_dir: Path | None, default_message: str | None = None) -> Reader:
    """A reader of samples whose messages come from ``schema_dir`` (default: the bundled schemas)."""
    if schema_dir is None:  # the bundled schemas load: only a stream of messages needs them (samples in SI do not)

        def bundled() -> tuple[Schema, ModuleType]:
            from ...frontends.loader import load
            from ..schemas.package import bundled_schemas, model_package

            schema = load([bundled_schemas()])
            return schema, model_package(schema, bundled_schemas())

        return Reader(None, None, default_message, bundled)
    from ...frontends.loader import load
    from ..schemas.package import model_package

    schema = load([schema_dir])
    return Reader(schema, model_package(schema, schema_dir), default_message)


def _instance_of(qualified: str, data: Mapping[str, Any]) -> int:
    """The battery a message is about: uORB battery_status.id is 1-based, MAVLink BATTERY_STATUS.id
    0-based; else battery 1."""
    ident = data.get("id")
    if isinstance(ident, int) and not isinstance(ident, bool):
        if qualified.startswith("uorb.") and 1 <= ident <= 16:
            return ident
        if qualified == "mavlink.BATTERY_STATUS" and 0 <= ident < 16:
            return ident + 1
    return 1


def read_parameter_values(path: Path) -> dict[str, float]:
    """Every parameter of a .param / .params file (every set of a QGC file merged, later sets
    winning); the failsafe takes the BATT*_ ones and the vehicle's own."""
    values: dict[str, float] = {}
    for _, group in parameter_files.read_parameter_file(path):
        values.update(group)
    return values


_BATT = re.compile(r"BATT[1-9A-G]?_")


def batt_parameter_count(values: Mapping[str, float]) -> int:
    """How many of ``values`` are battery monitor parameters (BATT_, BATT2_ .. BATT9_, BATTA_ ..
    BATTG_): without any, the failsafe would run, or a check pass, on defaults alone."""
    return sum(1 for name in values if _BATT.match(name))


class Replay:
    """Feeds a stream's samples to an evaluator; ``samples`` counts those read so far."""

    def __init__(self, failsafe: BatteryFailsafe, reader: Reader) -> None:
        self.failsafe = failsafe
        self.reader = reader
        self.samples = 0

    def run(self, path: Path, name: str, samples: Iterable[Sample] | None = None) -> Iterator[tuple[Event, Sample]]:
        """Every transition with the sample that caused it; errors name the stream as ``name``.
        ``samples`` replaces the JSON Lines reader (a flight log's samples). A stream of one plain shape is
        replayed over its columns (:mod:`.jsonl_columns`, :func:`.columnar.replay_columns`: the same events)."""
        if samples is None:
            fast = self._columnar(path)
            if fast is not None:
                yield from fast
                return
        for sample in self.reader.read(path) if samples is None else samples:
            self.samples += 1
            try:
                events = self.failsafe.update(
                    sample.t, sample.battery, armed=sample.armed, instance=sample.instance, **sample.extra
                )
            except ValueError as exc:
                raise BattgenError(f"{name}: {sample.place}: {exc}") from None
            yield from ((event, sample) for event in events)

    def _columnar(self, path: Path) -> list[tuple[Event, Sample]] | None:
        """The events of a plain-shaped stream replayed over its columns; None to read it sample by sample."""
        from ...inputs.files.held import held
        from .columnar import replay_columns  # numpy, for a plain stream's columns
        from .jsonl_columns import read_sample_columns

        file = path.as_posix()
        # held still (writers wait) while it is read through a map and its events' lines are read from that map
        with held(path, file) as hold:
            columns = read_sample_columns(path, mapped=hold.leased)
            if columns is None:
                return None

            def sample_at(k: int) -> Sample:
                return self.reader.sample(json.loads(columns.line(k)), file, k + 1)

            c = columns
            try:
                events = replay_columns(self.failsafe, c.t, c.instance, c.voltage, c.current, c.consumed, c.armed,
                                        sample_at)  # fmt: skip
            finally:
                if isinstance(c.data, mmap.mmap):
                    c.data.close()  # nothing reads it past the hold
        if events is not None:
            self.samples = len(c.t)
        return events
