"""``battgen validate [--message NAME] FILE...``: check data files against a message's generated validator.

Inputs, by extension (or ``--input-format``): JSON (.json), JSON Lines (.jsonl/.ndjson), YAML
(.yaml/.yml), devicetree (.dts/.dtsi/.dtb), parameter files (ArduPilot .param/.parm, QGroundControl
.params), PX4 flight logs (.ulg), MAVLink telemetry logs (.tlog) and raw MAVLink streams (.mav).

- Parameter files: one record per parameter set (per vehicle/component in a .params file) holding
  the message's parameters; a violation names its parameter's line. For params.BATT the failsafe
  cross-field checks (CRITICAL below LOW, thresholds below BATT_CAPACITY, plausible cell voltages,
  arming limits) are reported too.
- .ulg: every record of the message's topics (all multi_ids), located by topic, multi_id,
  timestamp and file offset. When the log's format for a topic differs from the schema's, the
  difference is printed once as a warning, the matching fields are checked, and the checks of the
  fields the log lacks or types differently are skipped (also said once).
- .tlog / .mav: every frame of the message, located by frame number, system/component id,
  sequence number and (tlog) time and offset; bad CRCs and garbage are one warning summary.

``--message`` may be omitted when the inputs imply a format with only one message in the schemas
(parameter files: params.BATT; MAVLink logs with the bundled schemas: mavlink.BATTERY_STATUS).

Prints one line per violation, ``file:line: message`` (``file: location: message`` for logs;
warnings marked, and not failing), notices about whole inputs and a summary on stderr; or with
``--format json`` one JSON document (each violation with its ``location``, each file with its
``notices``). Exit 0 valid, 1 violations, 2 unreadable input or unknown message.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..apps.failsafe.checks import NONNEGATIVE, check_params
from ..apps.models import model_class, model_package, resolve_message
from ..errors import BattgenError, LocatedError
from ..frontends.loader import load
from ..inputs.records import KIND_FORMATS, KINDS, Notice, Record, Unreadable, file_kind, read_records
from ..ir import Message, Schema, SourceFormat
from .main import project_root

EXIT_OK, EXIT_INVALID, EXIT_UNREADABLE = 0, 1, 2


@dataclass(frozen=True)
class Finding:
    """A violation of one record, placed in its file."""

    file: str
    line: int
    record: int
    where: str
    path: str
    rule: str
    value: object
    limit: object
    message: str
    severity: str
    location: Mapping[str, object] | None = None

    def text(self) -> str:
        mark = "warning: " if self.severity == "warning" else ""
        where = f"{self.where}: " if self.where else ""
        place = f"{self.file}:{self.line}" if self.line > 0 else self.file  # a .dtb or a log has no lines
        return f"{place}: {mark}{where}{self.message}"


@dataclass
class FileReport:
    file: str
    records: int = 0
    findings: list[Finding] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)
    notices: list[Notice] = field(default_factory=list)
    errors: int = 0
    warnings: int = 0


# A check beyond the generated validate(): (instance, its violations) -> findings as
# (severity, path, rule, value, message)
ExtraCheck = Callable[[Any, list[Any]], list[tuple[str, str, str, object, str]]]


def failsafe_check(instance: Any, violations: list[Any]) -> list[tuple[str, str, str, object, str]]:
    """codegen.apps.failsafe.checks over a BATT_* parameter set (absent parameters at their defaults,
    as ``battgen params --check`` does). A negative threshold the schema's range already reported
    is not reported twice: for a negative value that is the only finding check_params makes."""
    values = instance.to_dict()
    flagged = {str(v.path) for v in violations}
    out = []
    for f in check_params(values):
        value = values.get(f.param)
        if isinstance(value, int | float) and value < 0 and f.param in flagged:
            continue
        out.append((f.severity, f.param, "cross-field:failsafe", value, f.message))
    return out


def extra_check(message: Message) -> ExtraCheck | None:
    """The checks a message gets beyond its generated validate()."""
    names = {f.name for f in message.fields}
    if message.format is SourceFormat.PARAMS and set(NONNEGATIVE) <= names:
        return failsafe_check
    return None


def rule_fields(schema: Schema, message: Message) -> dict[str, frozenset[str]]:
    """Cross-field rule id -> the fields it reads (is_known() arguments included)."""
    from ..frontends.rules import bound_rules, referenced_fields

    out: dict[str, frozenset[str]] = {}
    for bound in bound_rules(schema, message):
        exprs = [bound.where, bound.check, bound.path, *(e for _, e in bound.bindings)]
        exprs += [p for p in bound.message if not isinstance(p, str)]
        names = {n for e in exprs for n in referenced_fields(e, skip_is_known=False)}
        out[bound.rule.id] = frozenset(names)
    return out


def _covers(skip: frozenset[str], path: str) -> bool:
    """True when ``path`` (``a``, ``a[3]``, ``a.b``) lies in a skipped field."""
    return any(path == s or path.startswith((s + ".", s + "[")) for s in skip)


class Checker:
    """Builds each record with the generated ``from_dict`` (or takes the instance a binary log
    decoded) and collects ``validate()``'s violations, minus those of fields the source lacks."""

    def __init__(
        self,
        cls: Any,
        message: Message,
        data_error: type[BaseException],
        rules: Mapping[str, frozenset[str]] | None = None,
        extra: ExtraCheck | None = None,
    ) -> None:
        self.cls = cls
        self.message = message
        self.data_error = data_error
        self.rules = rules or {}
        self.extra = extra

    def check(self, record: Record) -> list[Finding]:
        instance = record.instance
        if instance is None:
            try:
                instance = self.cls.from_dict(record.data)
            except self.data_error as exc:
                return [self._type_finding(record, exc)]
            except Exception as exc:  # a generated from_dict should raise DataError only; never a traceback
                return [self._finding(record, "", "type", record.data, None, f"cannot read the record: {exc}", "error")]
        validate = getattr(instance, "validate", None)
        if validate is None:
            return []
        try:
            violations = validate()
            extra = self.extra(instance, violations) if self.extra is not None else []
        except Exception as exc:
            return [self._finding(record, "", "internal", None, None, f"the validator failed: {exc!r}", "error")]
        if record.skip:
            violations = [v for v in violations if not self._skipped(v, record.skip)]
        findings = [
            self._finding(
                record,
                str(v.path),
                str(v.rule),
                v.value,
                v.limit,
                str(v.message),
                "warning" if v.severity == "warning" else "error",
            )
            for v in violations
        ]
        findings += [self._finding(record, p, rule, value, None, text, sev) for sev, p, rule, value, text in extra]
        return sorted(findings, key=lambda f: f.line)  # stable: the validator's order within a line

    def _skipped(self, v: Any, skip: frozenset[str]) -> bool:
        rule = str(v.rule)
        if rule.startswith("cross-field:") and self.rules.get(rule[len("cross-field:") :], frozenset()) & skip:
            return True
        return _covers(skip, str(v.path))

    def _type_finding(self, record: Record, exc: BaseException) -> Finding:
        path = str(getattr(exc, "path", ""))
        expected = str(getattr(exc, "expected", ""))
        value = getattr(exc, "value", None)
        prefix = f"{self.cls.__name__}"
        if path == prefix:
            path = ""
        elif path.startswith(prefix + "."):
            path = path[len(prefix) + 1 :]
        if expected.startswith("a field of "):
            text = f"{path} is not a field of {self.message.qualified_name}"
        else:
            text = f"{path or 'the record'}: expected {expected}, got {_short(value)}"
        return self._finding(record, path, "type", value, expected, text, "error")

    @staticmethod
    def _finding(
        record: Record, path: str, rule: str, value: object, limit: object, message: str, severity: str
    ) -> Finding:
        if path and path not in message:
            message = f"{path}: {message}"
        return Finding(
            record.file,
            record.line_of(path),
            record.index,
            record.where,
            path,
            rule,
            value,
            limit,
            message,
            severity,
            record.location,
        )


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _short(value: object, width: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def jsonable(value: object) -> Any:
    """``value`` as strict JSON data; NaN and infinities as the strings ``NaN``/``Infinity``/``-Infinity``."""
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "Infinity" if value > 0 else "-Infinity"
        return value
    if isinstance(value, bytes | bytearray):
        return list(value)
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, set | frozenset):
        return sorted((jsonable(v) for v in value), key=repr)
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    return str(value)


def check_file(path: Path, message: Message, checker: Checker, *, echo: bool, kind: str | None = None) -> FileReport:
    """Check every record of one file; with ``echo`` print each finding as it is found (streaming)."""
    report = FileReport(path.as_posix())
    try:
        for item in read_records(path, message, report.file, model=checker.cls, kind=kind):
            if isinstance(item, Notice):
                report.notices.append(item)
                if echo and item.severity == "warning":
                    print(f"{item.file}: warning: {item.message}", file=sys.stderr)
                continue
            if isinstance(item, Unreadable):
                report.unreadable.append(item)
                if echo:
                    place = f"{item.file}:{item.line}" if item.line > 0 else item.file
                    print(f"{place}: {item.message}", file=sys.stderr)
                continue
            report.records += 1
            for finding in checker.check(item):
                if finding.severity == "warning":
                    report.warnings += 1
                else:
                    report.errors += 1
                if echo:
                    print(finding.text())
                else:
                    report.findings.append(finding)
    except LocatedError as exc:  # instance, parameter-file and devicetree errors name file and line
        problem = Unreadable(exc.file, exc.line, exc.message)
        report.unreadable.append(problem)
        if echo:
            place = f"{exc.file}:{exc.line}" if exc.line > 0 else exc.file
            print(f"{place}: {exc.message}", file=sys.stderr)
    except BattgenError as exc:
        report.unreadable.append(Unreadable(report.file, 0, str(exc)))
        if echo:
            print(f"{report.file}: {exc}", file=sys.stderr)
    except Exception as exc:  # a reader's bug must still end in one line, never a traceback
        report.unreadable.append(Unreadable(report.file, 0, f"cannot read: {exc!r}"))
        if echo:
            print(f"{report.file}: cannot read: {exc!r}", file=sys.stderr)
    return report


def exit_code(reports: Iterable[FileReport]) -> int:
    code = EXIT_OK
    for report in reports:
        if report.unreadable:
            return EXIT_UNREADABLE
        if report.errors:
            code = EXIT_INVALID
    return code


def json_document(message: Message, reports: list[FileReport]) -> dict[str, Any]:
    return {
        "message": message.qualified_name,
        "valid": exit_code(reports) == EXIT_OK,
        "exit_code": exit_code(reports),
        "files": [
            {
                "file": r.file,
                "records": r.records,
                "errors": r.errors,
                "warnings": r.warnings,
                "unreadable": [{"file": u.file, "line": u.line, "message": u.message} for u in r.unreadable],
                "notices": [
                    {"kind": n.kind, "severity": n.severity, "message": n.message, "data": jsonable(n.data)}
                    for n in r.notices
                ],
                "violations": [
                    {
                        "file": f.file,
                        "line": f.line if f.line > 0 else None,
                        "record": f.record,
                        "node": f.where or None,
                        "location": jsonable(f.location),
                        "path": f.path,
                        "rule": f.rule,
                        "value": jsonable(f.value),
                        "limit": jsonable(f.limit),
                        "message": f.message,
                        "severity": f.severity,
                    }
                    for f in r.findings
                ],
            }
            for r in reports
        ],
    }


def default_message(schema: Schema, files: list[str], kind: str | None) -> str:
    """The message to check when --message is omitted: the only one of the inputs' format."""
    formats = set()
    for name in files:
        try:
            formats.add(KIND_FORMATS.get(kind or file_kind(Path(name)), ""))
        except LocatedError:
            formats.add("")
    candidates = [m.qualified_name for m in schema.messages if m.format.value in formats]
    if len(formats) == 1 and "" not in formats and len(candidates) == 1:
        return candidates[0]
    if len(formats) == 1 and "" not in formats and candidates:
        raise BattgenError(
            f"--message is required: the schemas hold {len(candidates)} such messages ({', '.join(candidates)})"
        )
    raise BattgenError("--message is required for these inputs (it may be omitted for parameter files)")


def make_checker(
    schema_dir: Path, message_name: str | None, files: list[str] | None = None, kind: str | None = None
) -> tuple[Message, Checker]:
    """Load the schemas, resolve the message (or the inputs' default one) and its generated class."""
    schema = load([schema_dir])
    if message_name is None:
        message_name = default_message(schema, files or [], kind)
    message = resolve_message(schema, message_name)
    package = model_package(schema, schema_dir, project_root())
    cls = model_class(package, message)
    meta = importlib.import_module(f"{package.__name__}._meta")
    data_error: type[BaseException] = getattr(meta, "DataError", ValueError)
    return message, Checker(cls, message, data_error, rule_fields(schema, message), extra_check(message))


def run(args: argparse.Namespace) -> int:
    schema_dir = Path(args.schemas) if args.schemas else project_root() / "schemas"
    kind = getattr(args, "input_format", None)
    message, checker = make_checker(schema_dir, args.message, args.files, kind)
    as_json = args.format == "json"
    reports = [check_file(Path(f), message, checker, echo=not as_json, kind=kind) for f in args.files]
    code = exit_code(reports)
    if as_json:
        json.dump(json_document(message, reports), sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        records = sum(r.records for r in reports)
        errors = sum(r.errors for r in reports)
        warnings = sum(r.warnings for r in reports)
        unreadable = sum(len(r.unreadable) for r in reports)
        summary = (
            f"{message.qualified_name}: {_count(records, 'record')} in {_count(len(reports), 'file')}, "
            f"{_count(errors, 'error')}, {_count(warnings, 'warning')}"
        )
        if unreadable:
            summary += f", {unreadable} unreadable"
        print(summary, file=sys.stderr)
    return code


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "validate",
        help="check data files, parameter files and flight/telemetry logs (.ulg, .tlog, .mav) against a message",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--message",
        metavar="NAME",
        help="qualified message name (uorb.BatteryStatus, mavlink.BATTERY_STATUS, params.BATT, ...) or an "
        "unambiguous short form; optional when the inputs' format has one message (parameter files: params.BATT)",
    )
    p.add_argument("--schemas", metavar="DIR", help="schema folder (default: the bundled schemas/)")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    p.add_argument(
        "--input-format",
        choices=KINDS,
        help="read every FILE as this format (default: from each extension; 'mavlink' is a raw MAVLink stream)",
    )
    p.add_argument(
        "files",
        nargs="+",
        metavar="FILE",
        help=".json, .yaml/.yml, .jsonl/.ndjson, .dts/.dtsi, .dtb, .param/.parm/.params, .ulg, .tlog or .mav",
    )
    p.set_defaults(func=run)
