"""The engine of ``battgen convert``: records of one format through a generated converter to another.

A :class:`Conversion` is one converter of a generated package's ``convert`` module, picked by its
sides (a side name, or a message of the side by qualified name or a dotted suffix of it), with a
policy and the extra inputs it takes. :meth:`Conversion.run` reads an input with the shared
readers (JSON, JSON Lines, YAML, hex or raw payloads, ULog, tlog, raw MAVLink) and hands out one
:class:`Converted` per record -- the plain data or the payloads of the target side, with the loss
report when asked -- and the notices a log reader has (format differences, damage skipped).
Errors name the input and the record's line (or a log record's location) and stop the run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Literal, Protocol, cast

from ...errors import BattgenError, cannot_read, did_you_mean
from ...inputs.documents import jsonl_rows, read_json, read_yaml
from ...inputs.files.kinds import content_kind, kind_of_name
from ...inputs.jsonl_blocks import jsonl_blocks, loads_line
from ...inputs.model import (
    DecodingClass,
    DronecanClass,
    Encodable,
    MavlinkClass,
    MessageClass,
    PlainClass,
    PlainData,
    UorbClass,
)
from ...inputs.payloads import read_hex, read_raw
from ...inputs.records import InputError, Item, Notice, Record, Unreadable
from ...ir.numbers import to_json_data
from ..schemas.package import bundled_schemas, load_schemas, named_package, package_module
from .jsonlines import integral, integral_line, orjson_line
from .senders import find_sender
from .strict import StrictCheck

FORMATS = ("json", "jsonl", "yaml", "hex", "raw")
BINARY_FORMATS = ("hex", "raw")
LOG_FORMATS = ("ulog", "tlog", "mavlink", "can", "dataflash", "dts", "dtb")  # input only
_EXTENSIONS = {".json": "json", ".jsonl": "jsonl", ".ndjson": "jsonl", ".yaml": "yaml", ".yml": "yaml"}
_EXTENSIONS |= {".hex": "hex", ".bin": "raw", ".raw": "raw", ".ulg": "ulog", ".tlog": "tlog", ".mav": "mavlink"}
_EXTENSIONS |= {".log": "can", ".asc": "can", ".blf": "can", ".trc": "can"}
_EXTENSIONS |= {".dts": "dts", ".dtsi": "dts", ".dtb": "dtb"}

# (alias, class) of each message of a side, the first required; the concept state is a side too
Side = tuple[tuple[str, PlainClass], ...]
Row = tuple[int, int, object]  # a JSON Lines record as read: (index, line, value); its Record made only if needed


class LossReport(Protocol):
    """The generated converters' record of what a conversion lost."""

    carried: dict[str, float]  # what the converter keeps for the next record

    def __len__(self) -> int: ...
    def to_dict(self) -> list[dict[str, str]]: ...
    def summary(self) -> str: ...
    def details(self, kind: str) -> list[tuple[str, str]]: ...


class ConvertModule(Protocol):
    """A generated package's ``convert`` module."""

    ENDPOINTS: Mapping[str, Side]
    CONVERTERS: Mapping[tuple[str, str], Callable[..., object]]
    POLICIES: Mapping[tuple[str, str], tuple[str, ...]]
    INPUTS: Mapping[tuple[str, str], tuple[str, ...]]
    ConversionError: type[Exception]

    def LossReport(self, *, full: bool = True) -> LossReport: ...  # the class, called to make one
    def converter(self, source: str, target: str) -> Callable[..., object]: ...


def input_format(path: str, given: str | None) -> str:
    """The format of an input: given, else a log's or capture's kind as its content says (:mod:`..inputs.kinds`),
    else from the extension (``.bin`` and ``.hex``: one message's bytes), else JSON Lines."""
    if given:
        return given
    kind = content_kind(Path(path))
    if kind in ("ulog", "tlog", "can", "dataflash"):  # a DataFlash .bin is a log, never one message's bytes
        return kind
    if kind_of_name(Path(path)) == "can":  # looks through .gz
        return "can"
    return _EXTENSIONS.get(Path(path).suffix.lower(), "jsonl")


def output_format(in_format: str, given: str | None) -> str:
    """The output format: given, else the input's (JSON Lines for binary input and logs)."""
    return given or ("jsonl" if in_format in (*BINARY_FORMATS, *LOG_FORMATS) else in_format)


def fail(where: str, line: int, message: str) -> BattgenError:
    return BattgenError(f"{where}:{line}: {message}" if line > 0 else f"{where}: {message}")


def converters(package: str | None) -> ConvertModule:
    """The ``convert`` module of a generated package, by the package's import name (None: the bundled one)."""
    try:
        return cast(ConvertModule, package_module(named_package(package), "convert"))
    except ImportError as exc:
        raise BattgenError(
            f"cannot import {package or 'generated'}.convert ({exc}); run 'battgen generate' first"
        ) from None


def side_name(module: ConvertModule, name: str) -> str:
    """A side given by its name, or by a message of it (qualified name or a dotted suffix)."""
    if name in module.ENDPOINTS:
        return name
    found = set()
    for side, items in module.ENDPOINTS.items():
        for _, cls in items:
            if not isinstance(cls, MessageClass):
                continue  # the concept state has no message name
            if name == cls.QUALIFIED_NAME or cls.QUALIFIED_NAME.endswith("." + name):
                found.add(side)
    if len(found) == 1:
        return found.pop()
    if found:
        raise BattgenError(f"{name!r} is ambiguous: it names a message of the sides {', '.join(sorted(found))}")
    return name  # unknown: reported with the known pairs


@dataclass(slots=True)  # not frozen: a frozen dataclass's __init__ costs twice as much, and one is made per record
class Converted:
    """One record converted: the target's plain data, or its payloads (binary output)."""

    line: int  # of the input record (0: a log record)
    plain: object = None
    payloads: tuple[bytes, ...] = ()
    loss: object = None  # the loss report's entries or summary, when asked for
    source: Mapping[str, object] | None = None  # where the record came from: file, record, line or log location
    # (field, detail) of each value the target could not hold, written as its "unknown" instead
    unrepresentable: tuple[tuple[str, str], ...] = ()
    text: bytes | None = None  # the plain data's JSON Lines bytes, when asked for and made at once (orjson)


class Endpoint:
    """How to build and write one side's objects (a tuple of messages, or the concept state)."""

    def __init__(self, name: str, items: Side) -> None:
        self.name = name
        self.items = items
        # the classes with a binary codec, looked up once (not per record)
        self.codecs = [cls if isinstance(cls, DecodingClass) else None for _, cls in items]
        self.aliases = frozenset(a for a, _ in items)

    def build(self, rec: Record) -> list[PlainData | None]:
        if rec.instance is not None:  # decoded already (a log record; a CAN node's other messages beside it)
            rest = list(rec.companions[: len(self.items) - 1])
            return [rec.instance, *rest, *([None] * (len(self.items) - 1 - len(rest)))]
        return self.build_data(rec.data, rec.file, rec.line)

    def build_data(self, data: object, file: str, line: int) -> list[PlainData | None]:
        """The side's objects from a record's plain data (or its payloads); errors name ``file:line``."""
        # the usual record, a bare object of the first message (no alias keys), built without the general walk
        if data.__class__ is dict and (
            len(cast(dict[str, Any], data)) > len(self.aliases)
            or not self.aliases.issuperset(cast(dict[str, Any], data))
        ):
            try:
                return [self.items[0][1].from_dict(cast(dict[str, Any], data)), *([None] * (len(self.items) - 1))]
            except BattgenError:
                raise
            except (ValueError, TypeError, KeyError) as exc:  # as below
                raise fail(file, line, f"invalid {self.name} record: {exc}") from None
        aliases = [a for a, _ in self.items]
        try:
            if isinstance(data, list) and data and all(isinstance(x, bytes) for x in data):
                return self._decode(data, file, line)
            if not isinstance(data, dict):
                raise fail(file, line, f"expected a {self.name} record (an object), got {type(data).__name__}")
            parts = (
                [data.get(a) for a in aliases]
                if len(aliases) > 1 and set(data) <= set(aliases)
                else [data, *([None] * (len(aliases) - 1))]
            )
            out: list[PlainData | None] = []
            for (alias, cls), part in zip(self.items, parts, strict=True):
                if part is None:
                    if alias == aliases[0]:
                        raise fail(file, line, f"expected the {alias} message of {self.name}")
                    out.append(None)
                elif not isinstance(part, dict):
                    raise fail(file, line, f"expected {alias} to be an object")
                else:
                    out.append(cls.from_dict(part))
            return out
        except BattgenError:
            raise
        except (ValueError, TypeError, KeyError) as exc:  # DataError / ConversionError are ValueErrors
            raise fail(file, line, f"invalid {self.name} record: {exc}") from None

    def _decode(self, payloads: list[bytes], file: str, line: int) -> list[PlainData | None]:
        out: list[PlainData | None] = []
        for i, ((alias, _), cls) in enumerate(zip(self.items, self.codecs, strict=True)):
            if i >= len(payloads):
                out.append(None)
                continue
            if cls is None:
                raise fail(file, line, f"{self.name} {alias} has no binary codec yet")
            out.append(cls.decode(payloads[i]))
        return out

    def to_line(self, objs: object) -> tuple[object, bytes] | None:
        """The plain data and its JSON Lines bytes (:func:`.jsonlines.orjson_line`) of a one-message side, when
        orjson writes them as json does: then they are strict JSON data as they are, with no walk of
        :func:`_json_data`. None for anything else."""
        if len(self.items) != 1:
            return None
        obj: Any = objs[0] if isinstance(objs, tuple) else objs
        data = obj.to_dict()
        text = integral_line(data) if integral(obj.__class__) else orjson_line(data)
        return None if text is None else (data, text)

    def to_plain(self, objs: object) -> object:
        seq = cast(tuple[PlainData | None, ...], objs if isinstance(objs, tuple) else (objs,))
        if len(self.items) == 1:
            return _json_data(cast(PlainData, seq[0]).to_dict())
        return {a: _json_data(o.to_dict()) for (a, _), o in zip(self.items, seq, strict=True) if o is not None}

    def to_binary(self, objs: object, file: str, line: int) -> tuple[bytes, ...]:
        seq = cast(tuple[object, ...], objs if isinstance(objs, tuple) else (objs,))
        out = []
        for (alias, _), o in zip(self.items, seq, strict=True):
            if o is None:
                continue
            if not isinstance(o, Encodable):
                raise fail(file, line, f"{self.name} {alias} has no binary codec yet")
            try:
                out.append(o.encode())
            except (ValueError, TypeError, OverflowError) as exc:
                raise fail(file, line, f"cannot encode {alias}: {exc}") from None
        return tuple(out)


_SCALARS = frozenset({int, str, bool, type(None)})
_NUMBERS = frozenset({int, bool, float})


def _json_data(data: dict[str, object]) -> object:
    """A message's ``to_dict()`` as strict JSON data: the dict itself when it holds only what JSON writes as it
    is (the usual record: finite numbers, text, flat lists of them), else :func:`to_json_data`'s copy (NaN and
    the infinities spelled, bytes and enum members made plain, nested messages walked). The types are taken
    a list at a time (``set(map(type, ...))``, at C speed), each value looked at only when a list holds a float."""
    value: Any
    for value in data.values():
        kind = value.__class__
        if kind is float:
            if value - value != 0.0:  # NaN or an infinity
                return to_json_data(data)
        elif kind is list:
            kinds = set(map(type, value))
            if float in kinds:
                # a sum of finite floats is finite unless it overflows (then the copy is made, and is the same)
                if not kinds <= _NUMBERS or (total := sum(value)) - total != 0.0:
                    return to_json_data(data)
            elif not kinds <= _SCALARS:
                return to_json_data(data)
        elif kind not in _SCALARS:
            return to_json_data(data)
    return data


CARRIED = "_before"  # the suffix of a converter input fed from the previous record's result


def _carried(result: object, report: object, field: str) -> float | None:
    """The value of ``field`` a converter carries to the next record: what its report says it keeps (a
    firmware's float total), else the field of its result (one object or a tuple of them); None if absent."""
    kept = getattr(report, "carried", None)
    if kept:  # (empty for most records: looked into only when something is kept)
        value = kept.get(field)
        if isinstance(value, float):
            return value
    for obj in result if isinstance(result, tuple) else (result,):
        value = getattr(obj, field, None)
        if value is not None and isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
    return None


class Conversion:
    """One converter of a generated package, checked: the pair exists, has the policy."""

    def _no_pair(self) -> str:
        """Why there is no converter: a side that does not exist (with the closest names), else the pair."""
        sides = {side for pair in self.module.CONVERTERS for side in pair}
        for option, name in (("--from", self.source_name), ("--to", self.target_name)):
            if name not in sides:
                return f"{option} {name!r}: expected a format or message, found no such name; " + did_you_mean(
                    name, sides, what="formats"
                )
        targets = sorted(t for s, t in self.module.CONVERTERS if s == self.source_name)
        return (
            f"no converter from {self.source_name} to {self.target_name}; from {self.source_name}: {', '.join(targets)}"
        )

    def __init__(
        self,
        package: str | None,
        source: str,
        target: str,
        policy: str,
        subjects: Sequence[str] = (),
        sender: str | None = None,
    ) -> None:
        self.module = converters(package)
        self.subjects = tuple(subjects)  # ``ID=TYPE`` pairs: the Cyphal types a capture's subjects carry
        self.source_name, self.target_name = side_name(self.module, source), side_name(self.module, target)
        key = (self.source_name, self.target_name)
        if key not in self.module.CONVERTERS:
            raise BattgenError(self._no_pair())
        if policy not in self.module.POLICIES[key]:
            raise BattgenError(
                f"{self.source_name} -> {self.target_name} has no {policy} policy (PX4 has no such code path)"
            )
        self.policy = policy
        self.bundled = package is None  # the bundled package: the bundled schemas' IR describes its classes
        self.func = self.module.CONVERTERS[key]
        self.inputs_taken: tuple[str, ...] = self.module.INPUTS.get(key, ())
        self.source = Endpoint(self.source_name, self.module.ENDPOINTS[self.source_name])
        self.target = Endpoint(self.target_name, self.module.ENDPOINTS[self.target_name])
        # a sender whose firmware states a value wrong in a known way (--sender): its records corrected first
        self.sender = find_sender(sender, self.source_name) if sender else None
        if self.sender is not None and policy != "strict":
            raise BattgenError(
                f"--sender {sender}: reads what the sender meant, the {policy} policy what {policy} does with what it "
                "receives; give one of them"
            )

    def run(
        self,
        source: Path | IO[bytes],
        where: str,
        fmt: str,
        *,
        binary: bool = False,
        loss: Literal["entries", "summary"] | None = None,
        inputs: Mapping[str, float] | None = None,
        lines: bool = False,
    ) -> Iterator[Converted | Notice]:
        """Convert every record of one input (``where`` names it) read as ``fmt``. ``binary``:
        hand out the target's payloads instead of its plain data; ``loss``: ``"entries"`` or
        ``"summary"`` of each record's loss report; ``lines``: with the plain data, its JSON Lines
        bytes where they are made at once (``Converted.text``)."""
        extra: dict[str, float | None] = dict(inputs or {})
        # an input named <field>_before is state the converter carries from record to record (PX4's
        # discharged-charge integral): unless given, each record gets the previous result's <field>
        taken = [name for name in self.inputs_taken if name.endswith(CARRIED) and name not in extra]
        carried = [(name, name.removesuffix(CARRIED)) for name in taken]
        carriers: dict[type, bool] = {}
        given = any_extra = any(value is not None for value in extra.values())
        # looked up once: this loop runs per record, and its own work is a good part of a JSON Lines run
        build, build_data, func, policy = self.source.build, self.source.build_data, self.func, self.policy
        new_report, full, sender = self.module.LossReport, loss is not None, self.sender
        # strict refuses a record validate finds an error in, judged as validate judges this kind of input
        strict = StrictCheck(fmt, bundled=self.bundled) if policy == "strict" else None
        conversion_error, to_plain, to_binary = self.module.ConversionError, self.target.to_plain, self.target.to_binary
        to_line = self.target.to_line
        report = new_report(full=full)
        lost_before = 0  # entries the last record's report holds (none: it is used again)
        for item in self._items(source, where, fmt):
            record: Record | None
            if item.__class__ is tuple:  # a JSON Lines record: (index, line, value), its Record made if needed
                index, line, data = item
                file, record = where, None
                objs = build_data(data, file, line)
            elif isinstance(item, Notice):
                yield item
                continue
            elif isinstance(item, Unreadable):
                raise fail(where, item.line, _reworded(item.message, item.reason, fmt))
            else:
                record = cast(Record, item)
                index, line, file = record.index, record.line, record.file
                objs = build(record)
            # always kept: what the target could not hold is told even without --report (the fields dropped
            # or left unknown, alike for every record, only with it); a report the last record left empty is
            # used again rather than a new one made for every record
            if lost_before or report.carried:
                report = new_report(full=full)
            if sender is not None:
                objs = sender.correct(objs, [a for a, _ in self.source.items], report)
            if strict is not None:  # after a sender's correction: what it meant is what is converted
                record = record or Record(index, line, data, file)
                strict.refuse(objs, record)
            try:
                if any_extra:
                    result = func(*objs, policy=policy, report=report, **extra)
                else:  # every input at its default, None: not passed (a call's keywords cost)
                    result = func(*objs, policy=policy, report=report)
            except conversion_error as exc:
                raise fail(file, line, f"record {index + 1}: cannot convert: {exc}") from None
            except (ValueError, TypeError, AttributeError) as exc:
                text = f"record {index + 1}: cannot convert (a value the input lacks or does not fit): {exc}"
                raise fail(file, line, text) from None
            if record is not None and record.location is not None:
                _keep_capture_time(result, record)
            if carried:
                holds = carriers.get(result.__class__)
                if holds is None:  # whether this result type has any of the carried fields (asked once a type)
                    holds = isinstance(result, tuple) or any(hasattr(result, f) for _, f in carried)
                    carriers[result.__class__] = holds
                if holds or report.carried:
                    for name, field in carried:
                        extra[name] = _carried(result, report, field)
                    any_extra = True
                else:  # nothing to carry: what _carried finds (None), without looking
                    for name, _ in carried:
                        extra[name] = None
                    any_extra = given
            lost_before = len(report)
            lost = None if loss is None else report.summary() if loss == "summary" else report.to_dict()
            unheld = tuple(report.details("unrepresentable")) if lost_before else ()
            # where the record came from: read only beside a loss (the report, a value the target cannot hold)
            at = None
            if unheld or lost is not None:
                at = _source(record or Record(index, line, data, file), where)
            if binary:
                payloads = to_binary(result, file, line)
                yield Converted(line, payloads=payloads, loss=lost, source=at, unrepresentable=unheld)
            elif lines and lost is None and (made := to_line(result)) is not None:
                yield Converted(line, plain=made[0], source=at, unrepresentable=unheld, text=made[1])
            else:
                yield Converted(line, plain=to_plain(result), loss=lost, source=at, unrepresentable=unheld)

    def _items(self, source: Path | IO[bytes], where: str, fmt: str) -> Iterator[Item | Row]:
        if fmt in LOG_FORMATS:
            yield from self._log_items(source, where, fmt)
            return
        if not isinstance(source, Path):
            yield from _stream_items(source, where, fmt)
            return
        if fmt == "jsonl":  # a file: a block of lines a step, as validate reads it (a stream: a line a step)
            yield from _block_rows(source, where)
            return
        try:
            stream = source.open("rb")
        except OSError as exc:
            raise BattgenError(f"{where}: {cannot_read(exc)}") from None
        with stream:
            yield from _stream_items(stream, where, fmt)

    def _log_items(self, source: Path | IO[bytes], where: str, fmt: str) -> Iterator[Item]:
        """Every record of the source side's first message in a .ulg, .tlog, raw MAVLink, CAN capture or
        devicetree (.dts, .dtb) input. The readers are imported here: a JSON Lines run loads none of them
        (python-can alone is half a second of start-up)."""
        from ...inputs.can.records import capture_side
        from ...inputs.tlog import StreamStats, mavlink_items, message_name
        from ...inputs.ulog.records import ulog_items

        cls = self.source.items[0][1]
        if fmt in ("dts", "dtb"):
            yield from _devicetree_items(source, where, fmt, cls)
            return
        if fmt == "dataflash" and not all(isinstance(c, DronecanClass) for _, c in self.source.items):
            raise BattgenError(
                f"{where}: expected a record file for --from {self.source_name}, found an ArduPilot DataFlash log "
                "(convert reads only the DroneCAN frames it logged, CANF/CAFD; 'battgen export' or 'report' read "
                "its BAT records)"
            )
        if fmt in ("can", "dataflash"):
            if not isinstance(source, Path):
                raise BattgenError(f"{where}: a CAN capture is read from a file, not from standard input")
            models = [c for _, c in self.source.items if isinstance(c, MessageClass)]
            for item in capture_side(source, where, models, self.subjects):
                if isinstance(item, Record):
                    yield Record(
                        item.index,
                        0,
                        None,
                        f"{where} ({item.where})",
                        instance=item.instance,
                        location=item.location,
                        companions=item.companions,
                    )
                elif isinstance(item, Unreadable):
                    raise BattgenError(f"{where}: {item.message}")
                elif item.severity != "info":
                    yield item
            return
        if fmt == "ulog":
            if not isinstance(cls, UorbClass):
                raise BattgenError(f"{where}: a ULog file holds uORB messages; {self.source_name} is not a uORB side")
            for item in ulog_items(source, where, cls):
                if isinstance(item, Record):
                    yield _located(item, where)
                elif isinstance(item, Notice) and item.kind == "unchecked" and item.data is not None:
                    fields = ", ".join(map(str, cast(list[str], item.data.get("fields", ()))))
                    text = f"{item.data.get('topic')}: not in the log, converted from the schema's defaults: {fields}"
                    yield Notice(item.file, text, item.kind, item.severity, item.data)
                elif isinstance(item, Unreadable):
                    raise BattgenError(f"{where}: {item.message}")
                else:
                    yield item
            return
        if not isinstance(cls, MavlinkClass):
            what = f"{self.source_name} is not a MAVLink side"
            raise BattgenError(f"{where}: a MAVLink log holds MAVLink messages; {what}")
        stats = StreamStats()
        for item in mavlink_items(source, where, cls, timestamps=fmt == "tlog", stats=stats):
            if isinstance(item, Record):
                yield _located(item, where)
        if stats.damaged:  # the summary without the last problem: a converted log is not a report
            yield Notice(where, stats.summary(message_name(cls)), "stream")


def _block_rows(path: Path, where: str) -> Iterator[Item | Row]:
    """A JSON Lines file's records as rows, :func:`...inputs.jsonl_blocks.jsonl_blocks`' values with their index."""
    index = 0
    for part in jsonl_blocks(path, where):
        if isinstance(part, Unreadable):
            yield part
            continue
        for line, value in part:
            yield index, line, value
            index += 1


def _stream_items(stream: IO[bytes], where: str, fmt: str) -> Iterator[Item | Row]:
    try:
        if fmt == "raw":
            yield from read_raw(stream, where)
        elif fmt == "hex":
            yield from read_hex(stream, where)
        elif fmt == "jsonl":
            yield from jsonl_rows(stream, where, loads=loads_line)
        elif fmt == "json":
            yield from read_json(stream, where)
        else:
            yield from read_yaml(stream, where)
    except InputError as exc:
        if not exc.reason:
            raise
        raise fail(where, exc.line, _reworded(exc.message, exc.reason, fmt)) from None


def _devicetree_items(source: Path | IO[bytes], where: str, fmt: str, cls: object) -> Iterator[Item]:
    """The battery nodes of a .dts/.dtb as records of the devicetree side (its binding read from the bundled
    schemas, as ``battgen validate`` reads them), each located by its node's line."""
    from ...inputs.devicetree.records import read_devicetree

    name = getattr(cls, "QUALIFIED_NAME", "")
    if not name.startswith("devicetree."):
        raise BattgenError(f"{where}: expected --from devicetree for a devicetree file, found --from side {name}")
    if not isinstance(source, Path):
        raise BattgenError(f"{where}: a devicetree file is read from a file, not from standard input")
    schema = load_schemas(bundled_schemas())
    try:
        message = schema.message(name)
    except KeyError:
        raise BattgenError(f"{where}: the bundled schemas have no binding {name}") from None
    for item in read_devicetree(source, where, message, binary=fmt == "dtb"):
        if isinstance(item, Unreadable):
            raise fail(item.file, item.line, item.message)
        yield item


def _keep_capture_time(result: object, item: Record) -> None:
    """A record of a CAN capture carries its time (``t``, s since the capture's first frame) though DroneCAN's
    BatteryInfo has no timestamp field: a uORB target's ``timestamp`` (µs) gets it, as PX4's bridge stamps
    the message with the time it arrived, rather than 0 on every record."""
    t = item.location.get("t") if item.location is not None and "frame" in item.location else None
    if isinstance(t, float) and getattr(result, "timestamp", None) == 0:
        setattr(result, "timestamp", round(t * 1e6))  # noqa: B010 (a generated class's field, by name)


def _source(item: Record, where: str) -> dict[str, object]:
    """Where a record came from, for the loss report: the input, the record's number (1-based),
    and its line or, for a log record, its location (topic, multi_id, timestamp, offset)."""
    out: dict[str, object] = {"file": where, "record": item.index + 1}
    if item.location is not None:
        out.update(item.location)
    elif item.line > 0:
        out["line"] = item.line
    return out


def _located(record: Record, where: str) -> Record:
    """A log record whose errors name the input and the record: ``file (topic multi_id 0, ...)``."""
    return Record(
        record.index,
        0,
        None,
        f"{where} ({record.where})",
        instance=record.instance,
        location=record.location,
        skip=record.skip,  # the fields the log lacks: strict judges them as validate does, not at all
    )


def _reworded(message: str, reason: str, fmt: str) -> str:
    """A reader's syntax error in convert's words (they name what a record is in each format)."""
    if not reason:
        return message
    if fmt == "jsonl":
        return f"expected one JSON record per line: {reason}"
    if fmt == "json":
        return f"expected JSON: {reason}"
    return f"expected YAML: {reason}"
