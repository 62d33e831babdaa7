"""The engine of ``battgen validate``: check the records of data files against a message's generated validator.

:func:`make_checker` loads the schemas and finds the message and its generated class;
:func:`check_file` reads one file's records (:mod:`codegen.inputs.dispatch`), builds each with the
generated ``from_dict`` (or takes the instance a binary log decoded), runs ``validate()`` and
the checks a message gets beyond it (the failsafe cross-field checks of a parameter set), and
collects the findings, notices and unreadable parts into a :class:`FileReport` -- handing each to
a callback as it is found, so that a caller can print them while a long file is still being read.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...errors import BattgenError, LocatedError
from ...inputs.dispatch import read_records
from ...inputs.files.kind_formats import KIND_FORMATS
from ...inputs.files.kinds import file_kind
from ...inputs.jsonl_blocks import jsonl_blocks
from ...inputs.model import GeneratedMessage, MessageClass, Violation
from ...inputs.records import Notice, Record, Unreadable
from ...ir import Message, Schema, SourceFormat
from ...ir.numbers import to_json_data
from ...text.brief import brief, clip, reportable
from ..failsafe.vehicles import detect_vehicle
from ..schemas.fits import left_out, rule_fields
from ..schemas.messages import BATTERY_MESSAGES, DATAFLASH_NOTE, resolve_message
from ..schemas.package import data_error, load_schemas, model_class, model_package
from .selection import Gate

EXIT_OK, EXIT_INVALID, EXIT_UNREADABLE = 0, 1, 2


@dataclass(frozen=True)
class Finding:
    """A violation of one record, placed in its file."""

    file: str
    line: int  # 0: a .dtb or a log, which have no lines
    record: int
    where: str
    path: str
    rule: str
    value: object
    limit: object
    message: str
    severity: str
    location: Mapping[str, object] | None = None
    waived: str = ""  # why it is left out of the verdict (--ignore, a profile's waiver); "" when reported


Event = Finding | Notice | Unreadable


@dataclass
class FileReport:
    """What checking one file found. ``findings`` stays empty when the caller took them as they came."""

    file: str
    records: int = 0
    findings: list[Finding] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)
    notices: list[Notice] = field(default_factory=list)
    errors: int = 0
    warnings: int = 0
    waived: int = 0  # findings left out by the rule selection or a profile (counted, not failing)


# A check beyond the generated validate(): (instance, its violations, the record's context, the
# vehicle asked for) -> findings as (severity, path, rule, value, message)
ExtraFinding = tuple[str, str, str, object, str]
ExtraCheck = Callable[
    [GeneratedMessage, Sequence[Violation], Mapping[str, object] | None, str | None], list[ExtraFinding]
]


def failsafe_check(
    instance: GeneratedMessage,
    violations: Sequence[Violation],
    context: Mapping[str, object] | None = None,
    vehicle: str | None = None,
    *,
    cells: int | None = None,
    chemistry: str = "lipo",
) -> list[ExtraFinding]:
    """codegen.apps.failsafe.checks over a parameter set: every battery's BATT*_ group (the whole set
    from the record's context; battery 1's absent parameters at the model's defaults), with the
    action codes of the vehicle given, else detected from the set (as ``battgen params --check`` and
    ``battgen failsafe`` do). Findings the schema's own checks made are not repeated."""
    from ..failsafe.checks import check_settings  # here: only a parameter set is checked so

    values: Mapping[str, object] = context if context is not None else instance.to_dict()
    flagged = {str(v.path) for v in violations}
    detection = detect_vehicle(values, vehicle)
    out = []
    for f in check_settings(values, vehicle=detection.vehicle, cells=cells, chemistry=chemistry):
        if f.param in flagged and f.severity == "error":
            continue
        out.append((f.severity, f.param, "cross-field:failsafe", values.get(f.param), f.message))
    return out


def extra_check(message: Message) -> ExtraCheck | None:
    """The checks a message gets beyond its generated validate()."""
    if message.format is not SourceFormat.PDEF:
        return None
    from ..failsafe.checks import NONNEGATIVE  # here: the failsafe's checks are imported for a parameter set alone

    return failsafe_check if set(NONNEGATIVE) <= {f.name for f in message.fields} else None


class Checker:
    """Builds each record with the generated ``from_dict`` (or takes the instance a binary log
    decoded) and collects ``validate()``'s violations, minus those of fields the source lacks."""

    def __init__(
        self,
        cls: MessageClass,
        message: Message,
        data_error: type[BaseException],
        rules: Mapping[str, frozenset[str]] | None = None,
        extra: ExtraCheck | None = None,
        vehicle: str | None = None,
    ) -> None:
        self.cls = cls
        self.message = message
        self.data_error = data_error
        self.rules = rules or {}
        self.extra = extra
        self.vehicle = vehicle  # the ArduPilot vehicle a parameter set is for (None: detect it)
        # a record is judged by from_dict and validate() alone: no checks beyond them, no devicetree node's reading
        self.plain = extra is None and message.devicetree is None

    def check(self, record: Record) -> list[Finding]:
        instance = record.instance
        if instance is None and self.message.devicetree is not None and isinstance(record.data, dict):
            return self._check_node(record, record.data)
        if instance is None:
            try:
                instance = self.cls.from_dict(record.data)
            except self.data_error as exc:
                return [self._type_finding(record, exc)]
            except Exception as exc:  # a generated from_dict should raise DataError only; never a traceback
                return [self._finding(record, "", "type", record.data, None, f"cannot read the record: {exc}", "error")]
        try:
            violations = instance.validate()
            extra = self.extra(instance, violations, record.context, self.vehicle) if self.extra is not None else []
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

    def _check_node(self, record: Record, data: dict[str, Any]) -> list[Finding]:
        """A devicetree node: every problem, in dt-validate's order (:mod:`.dt_problems`)."""
        from . import (
            devicetree as dt_problems,  # imported by devicetree input alone: it reads the devicetree frontend's tables
        )

        def problem(exc: BaseException) -> dt_problems.Problem:
            f = self._type_finding(record, exc)
            return dt_problems.Problem(f.path, f.rule, f.value, f.limit, f.message)

        # YAML allows a key of any kind (`?` alone is a null key); a devicetree property is named by text
        odd = [k for k in data if not isinstance(k, str)]
        data = {k: v for k, v in data.items() if isinstance(k, str)}
        instance, early = dt_problems.read_node(self.cls, self.message, data, self.data_error, problem)
        findings = [
            self._finding(
                record, "", dt_problems.UNKNOWN_RULE, None, None,
                f"{clip(repr(key))} is not a property name: a devicetree property is named by text", "error",
            )
            for key in odd
        ]  # fmt: skip
        findings += [self._finding(record, p.path, p.rule, p.value, p.limit, p.text, "error") for p in early]
        if instance is not None:
            try:
                violations = instance.validate()
            except Exception as exc:
                return [self._finding(record, "", "internal", None, None, f"the validator failed: {exc!r}", "error")]
            # a cross-field rule reading a property left out (it did not read) would judge its absence
            left_out = dt_problems.left_out_fields(self.message, data, early)
            violations = [v for v in violations if not self._skipped(v, left_out)]
            violations = [v for v in violations if not dt_problems.stood_in(str(v.path), early)]
            findings += [
                self._finding(
                    record, str(v.path), str(v.rule), v.value, v.limit, str(v.message),
                    "warning" if v.severity == "warning" else "error",
                )
                for v in violations
            ]  # fmt: skip
        return sorted(findings, key=lambda f: dt_problems.order_key(self.message, data, f.path, f.rule))

    def _skipped(self, v: Violation, skip: frozenset[str]) -> bool:
        return left_out(v, skip, self.rules)  # as convert --policy strict leaves it out (.fits)

    def _type_finding(self, record: Record, exc: BaseException) -> Finding:
        # the generated DataError names the field path, what was expected and the value found
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
            text = f"{path or 'the record'}: expected {expected}, got {brief(value)}"
        return self._finding(record, path, "type", value, expected, text, "error")

    @staticmethod
    def _finding(
        record: Record, path: str, rule: str, value: object, limit: object, message: str, severity: str
    ) -> Finding:
        shown = clip(path)
        if path and path not in message and shown not in message:
            message = f"{shown}: {message}"
        if len(path) > len(shown):  # a key thousands of characters long: messages name it briefly
            message = message.replace(path, shown)
        return Finding(
            record.file,
            record.line_of(path),
            record.index,
            record.where,
            path,
            rule,
            reportable(value),  # the report may be JSON: a hostile value is carried by its brief text
            reportable(limit),
            message,
            severity,
            record.location,
        )


def check_file(
    path: Path,
    message: Message,
    checker: Checker,
    *,
    kind: str | None = None,
    keep_findings: bool = True,
    on_event: Callable[[Event], None] | None = None,
    gate: Gate | None = None,
    subjects: Sequence[str] = (),
) -> FileReport:
    """Check every record of one file. Each finding, notice and unreadable part goes to
    ``on_event`` as soon as it is found; findings are kept in the report only with
    ``keep_findings`` (so a caller printing them streams a file of any size in constant memory).
    ``gate`` leaves findings out by rule selection or a profile: they are marked ``waived`` and
    counted, never errors. ``subjects``: which subject of a Cyphal/CAN capture carries which type (``ID=TYPE``)."""
    report = FileReport(path.as_posix())

    def tell(event: Event) -> None:
        if on_event is not None:
            on_event(event)

    def judge(record: Record) -> None:
        report.records += 1
        for finding in checker.check(record):
            reason = gate.why_not(finding.rule, finding.path) if gate is not None else None
            if reason is not None:
                finding = dataclasses.replace(finding, waived=reason)
                report.waived += 1
            elif finding.severity == "warning":
                report.warnings += 1
            else:
                report.errors += 1
            if keep_findings:
                report.findings.append(finding)
            tell(finding)

    def note(item: Notice | Unreadable) -> None:
        if isinstance(item, Notice):
            report.notices.append(item)
            if item.severity == "error":  # damage a reader found (a CAN transfer's bad CRC): a finding too
                report.errors += 1
        else:
            report.unreadable.append(item)
        tell(item)

    try:
        kind = kind or file_kind(path)
        if kind == "jsonl" and checker.plain:
            _check_json_lines(path, report, checker.cls, judge, note)
        else:
            for item in read_records(path, message, report.file, model=checker.cls, kind=kind, subjects=subjects):
                if isinstance(item, Record):
                    judge(item)
                else:
                    note(item)
    except LocatedError as exc:  # input, parameter-file and devicetree errors name file and line
        problem = Unreadable(exc.file, exc.line, exc.message)
    except BattgenError as exc:
        problem = Unreadable(report.file, 0, str(exc))
    except Exception as exc:  # a reader's bug must still end in one line, never a traceback
        problem = Unreadable(report.file, 0, f"cannot read: {exc!r}")
    else:
        return report
    report.unreadable.append(problem)
    tell(problem)
    return report


def _check_json_lines(
    path: Path,
    report: FileReport,
    cls: MessageClass,
    judge: Callable[[Record], None],
    note: Callable[[Unreadable], None],
) -> None:
    """A JSON Lines file of plain records, a block of lines at a time: a line that ``from_dict`` and
    ``validate()`` pass is counted, and only a line with findings becomes a Record and is checked
    again by :meth:`Checker.check`, which words them (what a file of valid records costs is the
    parse and the generated code, nothing per line beyond them)."""
    from_dict = cls.from_dict
    for part in jsonl_blocks(path, report.file):
        if isinstance(part, Unreadable):
            note(part)
            continue
        for line, data in part:
            try:
                if not from_dict(data).validate():  # data not a mapping: from_dict raises, and the check below words it
                    report.records += 1
                    continue
            except Exception:  # a record from_dict rejects: Checker.check words why
                pass
            judge(Record(report.records, line, data, report.file))


def is_empty(report: FileReport) -> bool:
    """A file that was read but held no record of the message."""
    return report.records == 0 and not report.unreadable


def exit_code(reports: Iterable[FileReport], *, allow_empty: bool = True) -> int:
    """0 when every record is valid, 1 when one has an error (or, unless ``allow_empty``, a file
    held no record at all), 2 when an input was unreadable."""
    code = EXIT_OK
    for report in reports:
        if report.unreadable:
            return EXIT_UNREADABLE
        if report.errors or (is_empty(report) and not allow_empty):
            code = EXIT_INVALID
    return code


def json_document(message: Message, reports: list[FileReport], *, allow_empty: bool = True) -> dict[str, object]:
    """The reports as one JSON document (``validate --format json``); waived findings are listed
    with their ``waived`` reason and not counted as errors or warnings."""
    code = exit_code(reports, allow_empty=allow_empty)
    return {
        "message": message.qualified_name,
        "valid": code == EXIT_OK,
        "exit_code": code,
        "files": [
            {
                "file": r.file,
                "records": r.records,
                "empty": is_empty(r),
                "errors": r.errors,
                "warnings": r.warnings,
                "waived": r.waived,
                "unreadable": [{"file": u.file, "line": u.line, "message": u.message} for u in r.unreadable],
                "notices": [
                    {"kind": n.kind, "severity": n.severity, "message": n.message, "data": to_json_data(n.data)}
                    for n in r.notices
                ],
                "violations": [
                    {
                        "file": f.file,
                        "line": f.line if f.line > 0 else None,
                        "record": f.record,
                        "node": f.where or None,
                        "location": to_json_data(f.location),
                        "path": f.path,
                        "rule": f.rule,
                        "value": to_json_data(f.value),
                        "limit": to_json_data(f.limit),
                        "message": f.message,
                        "severity": f.severity,
                        "waived": f.waived or None,
                    }
                    for f in r.findings
                ],
            }
            for r in reports
        ],
    }


def default_message(schema: Schema, files: list[str], kind: str | None) -> str:
    """The message to check when --message is omitted: for logs and captures their kind's battery message
    (:data:`.messages.BATTERY_MESSAGES`), else the only message of the inputs' format."""
    formats: set[SourceFormat | None] = set()
    kinds: set[str | None] = set()
    for name in files:
        try:
            found = kind or file_kind(Path(name))
        except LocatedError:
            found = None
        kinds.add(found)
        formats.add(KIND_FORMATS.get(found) if found is not None else None)
    batteries = {BATTERY_MESSAGES.get(k) if k is not None else None for k in kinds}
    qualified = {m.qualified_name for m in schema.messages}
    if len(batteries) == 1 and None not in batteries:
        (battery,) = batteries
        if battery in qualified:
            return str(battery)
    if kinds == {"dataflash"}:
        raise BattgenError(f"--message is required: {DATAFLASH_NOTE}")
    candidates = [m.qualified_name for m in schema.messages if m.format in formats]
    if len(formats) == 1 and None not in formats and len(candidates) == 1:
        return candidates[0]
    if len(formats) == 1 and None not in formats and candidates:
        raise BattgenError(
            f"--message is required: the schemas hold {len(candidates)} such messages ({', '.join(candidates)})"
        )
    raise BattgenError("--message is required for these inputs (it may be omitted for parameter files)")


def make_checker(
    schema_dir: Path,
    message_name: str | None,
    files: list[str] | None = None,
    kind: str | None = None,
    vehicle: str | None = None,
    *,
    only: Collection[str] | None = None,
) -> tuple[Message, Checker]:
    """Load the schemas, resolve the message (or the inputs' default one) and its generated class. ``only``: the
    sub-folders of the schema folder to read (the message's format and the rules, where the caller knows it)."""
    schema = load_schemas(schema_dir, only=only)
    if message_name is None:
        message_name = default_message(schema, files or [], kind)
    message = resolve_message(schema, message_name)
    package = model_package(schema, schema_dir)
    cls = model_class(package, message)
    extra = extra_check(message)
    return message, Checker(cls, message, data_error(package), rule_fields(schema, message), extra, vehicle)
