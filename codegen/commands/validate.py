"""``battgen validate --message NAME FILE...``: check data files against a message's generated validator.

Prints one line per violation, ``file:line: message`` (warnings marked, and not failing), or with
``--format json`` one JSON document. Exit 0 valid, 1 violations, 2 unreadable input or unknown message.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..cli import project_root
from ..errors import BattgenError, SchemaError
from ..instances import InstanceError, Record, Unreadable, read_records
from ..ir import Message
from ..loader import load
from ..models import model_class, model_package, resolve_message

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

    def text(self) -> str:
        mark = "warning: " if self.severity == "warning" else ""
        where = f"{self.where}: " if self.where else ""
        place = f"{self.file}:{self.line}" if self.line > 0 else self.file  # a .dtb has no lines
        return f"{place}: {mark}{where}{self.message}"


@dataclass
class FileReport:
    file: str
    records: int = 0
    findings: list[Finding] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)
    errors: int = 0
    warnings: int = 0


class Checker:
    """Builds each record with the generated ``from_dict`` and collects ``validate()``'s violations."""

    def __init__(self, cls: Any, message: Message, data_error: type[BaseException]) -> None:
        self.cls = cls
        self.message = message
        self.data_error = data_error

    def check(self, record: Record) -> list[Finding]:
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
        except Exception as exc:
            return [self._finding(record, "", "internal", None, None, f"the validator failed: {exc!r}", "error")]
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
        return sorted(findings, key=lambda f: f.line)  # stable: the validator's order within a line

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
            record.file, record.line_of(path), record.index, record.where, path, rule, value, limit, message, severity
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


def check_file(path: Path, message: Message, checker: Checker, *, echo: bool) -> FileReport:
    """Check every record of one file; with ``echo`` print each finding as it is found (streaming)."""
    report = FileReport(path.as_posix())
    try:
        for item in read_records(path, message, report.file):
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
    except (InstanceError, SchemaError) as exc:  # a devicetree reader's SchemaError names file and line too
        problem = Unreadable(exc.file, exc.line, exc.message)
        report.unreadable.append(problem)
        if echo:
            place = f"{exc.file}:{exc.line}" if exc.line > 0 else exc.file
            print(f"{place}: {exc.message}", file=sys.stderr)
    except BattgenError as exc:
        report.unreadable.append(Unreadable(report.file, 0, str(exc)))
        if echo:
            print(f"{report.file}: {exc}", file=sys.stderr)
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
                "violations": [
                    {
                        "file": f.file,
                        "line": f.line if f.line > 0 else None,
                        "record": f.record,
                        "node": f.where or None,
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


def make_checker(schema_dir: Path, message_name: str) -> tuple[Message, Checker]:
    """Load the schemas, resolve the message and its generated class."""
    schema = load([schema_dir])
    message = resolve_message(schema, message_name)
    package = model_package(schema, schema_dir, project_root())
    cls = model_class(package, message)
    meta = importlib.import_module(f"{package.__name__}._meta")
    data_error: type[BaseException] = getattr(meta, "DataError", ValueError)
    return message, Checker(cls, message, data_error)


def run(args: argparse.Namespace) -> int:
    schema_dir = Path(args.schemas) if args.schemas else project_root() / "schemas"
    message, checker = make_checker(schema_dir, args.message)
    as_json = args.format == "json"
    reports = [check_file(Path(f), message, checker, echo=not as_json) for f in args.files]
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
        help="check JSON, YAML, JSON Lines or devicetree (.dts/.dtb) data files against a message",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--message",
        required=True,
        metavar="NAME",
        help="qualified message name (uorb.BatteryStatus, mavlink.BATTERY_STATUS, ...) or an unambiguous short form",
    )
    p.add_argument("--schemas", metavar="DIR", help="schema folder (default: the bundled schemas/)")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    p.add_argument("files", nargs="+", metavar="FILE", help=".json, .yaml/.yml, .jsonl/.ndjson, .dts/.dtsi or .dtb")
    p.set_defaults(func=run)
