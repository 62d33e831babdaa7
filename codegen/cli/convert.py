"""``battgen convert``: move battery records between formats with the generated converters.

Records come as JSON (an object or an array of them), JSON Lines (streamed, one record a line),
YAML (a mapping or a list; several documents allowed), or binary payloads (``hex``: one record a
line, the payloads of a multi-message side separated by spaces; ``raw``: one payload a file)
decoded and encoded by the generated codecs. A record of a side with several messages
(DroneCAN: BatteryInfo plus BatteryInfoAux) is keyed by alias (``{"info": {...}, "aux": {...}}``);
a bare object is the first message. Errors name the input and record line; exit code 2.

Logs convert every record they hold: PX4 flight logs (``ulog``, .ulg: every record of the source
uORB message's topics, all multi_ids, in file order; a log format that differs from the schema is
one warning on stderr, and fields the log lacks keep their defaults), MAVLink telemetry logs
(``tlog``, .tlog) and raw MAVLink streams (``mavlink``, .mav): every frame of the source message,
with bad CRCs and garbage skipped and summed up in one warning. ``--from``/``--to`` take a side
name or a message name (``uorb.BatteryStatus``, ``mavlink.BATTERY_STATUS``).
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import IO, Any

from ..errors import BattgenError

FORMATS = ("json", "jsonl", "yaml", "hex", "raw")
LOG_FORMATS = ("ulog", "tlog", "mavlink")  # input only
_EXTENSIONS = {".json": "json", ".jsonl": "jsonl", ".ndjson": "jsonl", ".yaml": "yaml", ".yml": "yaml"}
_EXTENSIONS |= {".hex": "hex", ".bin": "raw", ".raw": "raw", ".ulg": "ulog", ".tlog": "tlog", ".mav": "mavlink"}


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "convert", help="convert battery records between formats (JSON, JSON Lines, YAML, binary)"
    )
    p.add_argument("--from", dest="source", required=True, help="source side (dronecan, uorb, uorb_v0, mavlink, ...)")
    p.add_argument("--to", dest="target", required=True, help="target side, or 'concepts' for the shared state")
    p.add_argument("--policy", choices=("strict", "px4"), default="strict", help="strict (default) or px4")
    p.add_argument("--report", action="store_true", help="add each record's loss report (to stderr for binary output)")
    p.add_argument(
        "--report-summary",
        action="store_true",
        help="as --report, but the loss as a short text: one line per kind, fields grouped by message",
    )
    p.add_argument("files", nargs="*", help="input files (default: standard input)")
    p.add_argument("-o", "--output", help="output file (default: standard output)")
    p.add_argument(
        "--in-format",
        "--input-format",
        choices=FORMATS + LOG_FORMATS,
        help="input format (default: from the extension, else jsonl; .ulg ulog, .tlog tlog, .mav mavlink)",
    )
    p.add_argument("--out-format", choices=FORMATS, help="output format (default: the input's, text for binary)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="extra converter input (number)")
    p.add_argument("--package", default="generated", help="the generated package to use (default: generated)")
    p.set_defaults(func=run)


class _Record:
    __slots__ = ("data", "line", "objs", "where")

    def __init__(self, data: Any, where: str, line: int, objs: list[Any] | None = None) -> None:
        self.data = data
        self.where = where
        self.line = line  # 0: a log record, located by ``where``
        self.objs = objs  # already decoded (logs)


def _fail(where: str, line: int, message: str) -> BattgenError:
    return BattgenError(f"{where}:{line}: {message}" if line > 0 else f"{where}: {message}")


def _log_records(source: Path | IO[bytes], where: str, fmt: str, side: _Side) -> Iterator[_Record]:
    """Every record of the side's first message in a .ulg, .tlog or raw MAVLink input."""
    cls = side.items[0][1]
    pad: list[Any] = [None] * (len(side.items) - 1)
    if fmt == "ulog":
        from ..inputs.records import Unreadable
        from ..inputs.ulog import UlogReader

        if not hasattr(cls, "ulog_format"):
            raise BattgenError(f"{where}: a ULog file holds uORB messages; {side.name} is not a uORB side")
        reader = UlogReader(source, where, cls)
        try:
            for notice in reader.notices:
                text = notice.message
                if notice.kind == "unchecked" and notice.data is not None:
                    fields = ", ".join(map(str, notice.data.get("fields", ())))  # type: ignore[call-overload]
                    text = f"{notice.data.get('topic')}: not in the log, converted from the schema's defaults: {fields}"
                if notice.severity == "warning":
                    print(f"{where}: warning: {text}", file=sys.stderr)
            for rec in reader.records():
                if isinstance(rec, Unreadable):
                    raise BattgenError(f"{where}: {rec.message}")
                yield _Record(None, f"{where} ({rec.where()})", 0, [rec.instance, *pad])
            for notice in reader.trailing:  # damage and "no records": known only after the whole walk
                if notice.severity == "warning":
                    print(f"{where}: warning: {notice.message}", file=sys.stderr)
        finally:
            reader.close()
        return
    from ..inputs.tlog import StreamStats, read_frames

    if not hasattr(cls, "MSG_ID"):
        raise BattgenError(f"{where}: a MAVLink log holds MAVLink messages; {side.name} is not a MAVLink side")
    stats = StreamStats()
    name = getattr(cls, "QUALIFIED_NAME", cls.__name__).rpartition(".")[2]
    for frame in read_frames(source, where, cls, stats, timestamps=fmt == "tlog"):
        yield _Record(None, f"{where} ({frame.where(name)})", 0, [frame.instance, *pad])
    if stats.damaged:
        print(f"{where}: warning: {stats.summary(name)}", file=sys.stderr)


def _read_records(stream: IO[bytes], where: str, fmt: str) -> Iterator[_Record]:
    if fmt == "raw":
        yield _Record(stream.read(), where, 1)
        return
    if fmt in ("jsonl", "hex"):
        for n, raw in enumerate(stream, start=1):
            text = raw.decode("utf-8", "replace").strip()
            if not text:
                continue
            if fmt == "hex":
                try:
                    yield _Record([bytes.fromhex(part) for part in text.split()], where, n)
                except ValueError:
                    raise _fail(where, n, "expected hexadecimal payloads") from None
            else:
                try:
                    yield _Record(json.loads(text), where, n)
                except json.JSONDecodeError as exc:
                    raise _fail(where, n, f"expected one JSON record per line: {exc.msg}") from None
        return
    text = stream.read().decode("utf-8", "replace")
    if fmt == "json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise _fail(where, exc.lineno, f"expected JSON: {exc.msg}") from None
        for item in data if isinstance(data, list) else [data]:
            yield _Record(item, where, 1)
        return
    yield from _yaml_records(text, where)


def _yaml_records(text: str, where: str) -> Iterator[_Record]:
    import yaml

    try:
        nodes = list(yaml.compose_all(text, Loader=yaml.SafeLoader))
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise _fail(where, mark.line + 1 if mark else 1, f"expected YAML: {exc}") from None
    for node in nodes:
        if node is None:
            continue
        items = node.value if isinstance(node, yaml.SequenceNode) else [node]
        for item in items:
            data = yaml.SafeLoader("").construct_document(item)
            yield _Record(data, where, item.start_mark.line + 1)


def _plain(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


class _Side:
    """How to build and print one side's objects (a tuple of messages, or the concept state)."""

    def __init__(self, name: str, items: tuple[tuple[str, type[Any]], ...]) -> None:
        self.name = name
        self.items = items

    def build(self, rec: _Record) -> list[Any]:
        if rec.objs is not None:
            return rec.objs
        data = rec.data
        aliases = [a for a, _ in self.items]
        try:
            if isinstance(data, list) and data and all(isinstance(x, bytes) for x in data):
                return self._decode(data, rec)
            if isinstance(data, bytes):
                return self._decode([data], rec)
            if not isinstance(data, dict):
                raise _fail(
                    rec.where, rec.line, f"expected a {self.name} record (an object), got {type(data).__name__}"
                )
            parts = (
                [data.get(a) for a in aliases]
                if len(aliases) > 1 and set(data) <= set(aliases)
                else [data, *([None] * (len(aliases) - 1))]
            )
            out: list[Any] = []
            for (alias, cls), part in zip(self.items, parts, strict=True):
                if part is None:
                    if alias == aliases[0]:
                        raise _fail(rec.where, rec.line, f"expected the {alias} message of {self.name}")
                    out.append(None)
                elif not isinstance(part, dict):
                    raise _fail(rec.where, rec.line, f"expected {alias} to be an object")
                else:
                    out.append(cls.from_dict(part))
            return out
        except BattgenError:
            raise
        except (ValueError, TypeError, KeyError) as exc:  # DataError / ConversionError are ValueErrors
            raise _fail(rec.where, rec.line, f"invalid {self.name} record: {exc}") from None

    def _decode(self, payloads: list[bytes], rec: _Record) -> list[Any]:
        out: list[Any] = []
        for i, (alias, cls) in enumerate(self.items):
            if i >= len(payloads):
                out.append(None)
                continue
            if not hasattr(cls, "decode"):
                raise _fail(rec.where, rec.line, f"{self.name} {alias} has no binary codec yet")
            out.append(cls.decode(payloads[i]))
        return out

    def to_plain(self, objs: Any) -> Any:
        seq = objs if isinstance(objs, tuple) else (objs,)
        if len(self.items) == 1:
            return _plain(seq[0].to_dict())
        return {a: _plain(o.to_dict()) for (a, _), o in zip(self.items, seq, strict=True) if o is not None}

    def to_binary(self, objs: Any, rec: _Record) -> list[bytes]:
        seq = objs if isinstance(objs, tuple) else (objs,)
        out = []
        for (alias, _), o in zip(self.items, seq, strict=True):
            if o is None:
                continue
            if not hasattr(o, "encode"):
                raise _fail(rec.where, rec.line, f"{self.name} {alias} has no binary codec yet")
            try:
                out.append(o.encode())
            except (ValueError, TypeError, OverflowError) as exc:
                raise _fail(rec.where, rec.line, f"cannot encode {alias}: {exc}") from None
        return out


def _package(name: str) -> ModuleType:
    root = Path.cwd()
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    try:
        return importlib.import_module(f"{name}.convert")
    except ImportError as exc:
        raise BattgenError(f"cannot import {name}.convert ({exc}); run 'battgen generate' first") from None


def _inputs(settings: list[str]) -> dict[str, float]:
    out = {}
    for item in settings:
        name, eq, value = item.partition("=")
        try:
            if not eq:
                raise ValueError
            out[name.strip()] = float(value)
        except ValueError:
            raise BattgenError(f"--set {item!r}: expected NAME=NUMBER") from None
    return out


def _side_name(pkg: ModuleType, name: str) -> str:
    """A side given by its name, or by a message of it (qualified name or a dotted suffix)."""
    if name in pkg.ENDPOINTS:
        return name
    found = set()
    for side, items in pkg.ENDPOINTS.items():
        for _, cls in items:
            qualified = str(getattr(cls, "QUALIFIED_NAME", ""))
            if name == qualified or qualified.endswith("." + name):
                found.add(side)
    if len(found) == 1:
        return str(found.pop())
    if found:
        raise BattgenError(f"{name!r} is ambiguous: it names a message of the sides {', '.join(sorted(found))}")
    return name  # unknown: reported with the known pairs


def run(args: argparse.Namespace) -> int:
    pkg = _package(args.package)
    args.source, args.target = _side_name(pkg, args.source), _side_name(pkg, args.target)
    key = (args.source, args.target)
    if key not in pkg.CONVERTERS:
        pairs = ", ".join(f"{s}->{t}" for s, t in sorted(pkg.CONVERTERS))
        raise BattgenError(f"no converter from {args.source!r} to {args.target!r} (known pairs: {pairs})")
    if args.policy not in pkg.POLICIES[key]:
        raise BattgenError(f"{args.source} -> {args.target} has no {args.policy} policy (PX4 has no such code path)")
    func: Callable[..., Any] = pkg.CONVERTERS[key]
    extra = _inputs(args.set)
    allowed = pkg.INPUTS.get(key, ())
    for name in extra:
        if name not in allowed:
            raise BattgenError(
                f"--set {name}: not an input of {args.source} -> {args.target} ({', '.join(allowed) or 'none'})"
            )
    source = _Side(args.source, pkg.ENDPOINTS[args.source])
    target = _Side(args.target, pkg.ENDPOINTS[args.target])
    out_stream: IO[bytes] = open(args.output, "wb") if args.output else sys.stdout.buffer
    try:
        for path in args.files or ["-"]:
            fmt = args.in_format or _EXTENSIONS.get(Path(path).suffix.lower(), "jsonl")
            out_fmt = args.out_format or ("jsonl" if fmt in ("hex", "raw", *LOG_FORMATS) else fmt)
            where = "<stdin>" if path == "-" else path
            if fmt in LOG_FORMATS and path != "-":  # read by path: memory-mapped
                records = _log_records(Path(path), where, fmt, source)
                _convert_stream(pkg, func, args, extra, source, target, records, where, fmt, out_fmt, out_stream)
                continue
            try:
                stream: IO[bytes] = sys.stdin.buffer if path == "-" else open(path, "rb")
            except OSError as exc:
                raise BattgenError(f"{path}: cannot read: {exc.strerror or exc}") from None
            with stream:
                records = (
                    _log_records(stream, where, fmt, source)
                    if fmt in LOG_FORMATS
                    else _read_records(stream, where, fmt)
                )
                _convert_stream(pkg, func, args, extra, source, target, records, where, fmt, out_fmt, out_stream)
    finally:
        if args.output:
            out_stream.close()
    return 0


def _loss(report: Any, args: argparse.Namespace) -> Any:
    """The record's loss report: every entry (--report), or its summary text (--report-summary)."""
    return report.summary() if args.report_summary and not args.report else report.to_dict()


def _convert_stream(
    pkg: ModuleType,
    func: Callable[..., Any],
    args: argparse.Namespace,
    extra: dict[str, float],
    source: _Side,
    target: _Side,
    records: Iterator[_Record],
    where: str,
    fmt: str,
    out_fmt: str,
    out: IO[bytes],
) -> None:
    collected: list[Any] = []
    for rec in records:
        objs = source.build(rec)
        report = pkg.LossReport() if args.report or args.report_summary else None
        try:
            result = func(*objs, policy=args.policy, report=report, **extra)
        except pkg.ConversionError as exc:
            raise _fail(where, rec.line, f"cannot convert: {exc}") from None
        except (ValueError, TypeError, AttributeError) as exc:
            raise _fail(where, rec.line, f"cannot convert (a value the input lacks or does not fit): {exc}") from None
        if out_fmt in ("hex", "raw"):
            payloads = target.to_binary(result, rec)
            out.write(b" ".join(p.hex().encode() for p in payloads) + b"\n" if out_fmt == "hex" else b"".join(payloads))
            if report is not None:
                sys.stderr.write(json.dumps({"line": rec.line, "loss": _loss(report, args)}) + "\n")
            continue
        plain = target.to_plain(result)
        record = {"record": plain, "loss": _loss(report, args)} if report is not None else plain
        if out_fmt == "jsonl":
            out.write(json.dumps(record, allow_nan=False).encode() + b"\n")
            out.flush()
        else:
            collected.append(record)
    if out_fmt == "json":
        data = collected[0] if len(collected) == 1 and fmt == "json" else collected
        out.write(json.dumps(data, indent=2, allow_nan=False).encode() + b"\n")
    elif out_fmt == "yaml":
        import yaml

        data = collected[0] if len(collected) == 1 else collected
        out.write(yaml.safe_dump(data, sort_keys=False).encode())
