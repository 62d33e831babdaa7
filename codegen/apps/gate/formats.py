"""``battgen validate``'s findings grouped, and written for CI systems: GitHub Actions workflow
commands and SARIF 2.1.0 (code scanning).

Findings repeat: a log of 62,800 records breaking one rule gives 62,800 identical findings. A
:class:`Group` holds the findings of one file with the same severity, rule and field (array indexes
ignored), with the first and last and their count; groups keep the order in which they first
appeared. Waived findings (``--ignore``, a profile) are grouped apart and, in SARIF, written as
suppressed results carrying their reason; GitHub annotations leave them out.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

from ...text.escape import github_data, github_property
from .selection import Settings, field_of, finding_code
from .validate import Finding

SARIF_SCHEMA = "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"
MAX_GROUPS = 10_000  # distinct (file, severity, rule, field) kept; more are counted, not listed


@dataclass
class Group:
    """Findings of one file alike but for the record: the first, the last, how many."""

    first: Finding
    last: Finding
    count: int = 1

    @property
    def code(self) -> str:
        return finding_code(self.first.rule, self.first.path)

    def repeats(self) -> str:
        """`` (and 41 more records like it, the last: <where>)`` when the finding repeats."""
        if self.count == 1:
            return ""
        last = self.last.where or (f"line {self.last.line}" if self.last.line > 0 else f"record {self.last.record}")
        more = self.count - 1
        return f" (and {more} more record{'s' if more > 1 else ''} like it, the last: {last})"


class Grouper:
    """Groups findings as they come; memory bounded by the number of distinct groups."""

    def __init__(self) -> None:
        self._groups: dict[tuple[str, str, str, str, str], Group] = {}
        self.overflow = 0  # findings of groups beyond MAX_GROUPS

    def add(self, finding: Finding) -> None:
        key = (finding.file, finding.waived, finding.severity, finding.rule, field_of(finding.path))
        group = self._groups.get(key)
        if group is not None:
            group.last = finding
            group.count += 1
        elif len(self._groups) < MAX_GROUPS:
            self._groups[key] = Group(finding, finding)
        else:
            self.overflow += 1

    def groups(self, *, waived: bool = False) -> list[Group]:
        return [g for g in self._groups.values() if bool(g.first.waived) == waived]


def github_line(group: Group) -> str:
    """A GitHub Actions workflow command annotating the group's file (and line, when it has one)."""
    f = group.first
    command = "warning" if f.severity == "warning" else "error"
    props = [f"file={github_property(f.file)}"]
    if f.line > 0:
        props.append(f"line={f.line}")
    props.append(f"title={github_property('battgen ' + group.code)}")
    where = f"{f.where}: " if f.where else ""
    return f"::{command} {','.join(props)}::{github_data(where + f.message + group.repeats())}"


def github_notice(file: str, message: str) -> str:
    """A workflow command for a problem with a whole input (unreadable, no records)."""
    return f"::error file={github_property(file)},title=battgen::{github_data(message)}"


def _uri(file: str) -> str:
    path = Path(file)
    text = path.as_posix() if not path.is_absolute() else path.resolve().as_uri()
    return text if text.startswith("file:") else quote(text)


def _result(group: Group, rule_index: Mapping[str, int]) -> dict[str, object]:
    f = group.first
    location: dict[str, object] = {"artifactLocation": {"uri": _uri(f.file)}}
    if f.line > 0:
        location["region"] = {"startLine": f.line}
    where = f"{f.where}: " if f.where else ""
    result: dict[str, object] = {
        "ruleId": group.code,
        "ruleIndex": rule_index[group.code],
        "level": "warning" if f.severity == "warning" else "error",
        "message": {"text": where + f.message + group.repeats()},
        "locations": [{"physicalLocation": location}],
        "properties": {"count": group.count, "rule": f.rule, "field": field_of(f.path)},
    }
    if f.waived:
        result["suppressions"] = [{"kind": "external", "justification": f.waived}]
    return result


def sarif_document(
    message: str,
    groups: Sequence[Group],
    problems: Iterable[tuple[str, str, str]],
    settings: Settings,
    exit_code: int,
    version: str,
) -> dict[str, object]:
    """One SARIF 2.1.0 log: a run of battgen, a rule per finding code, a result per group (waived
    ones suppressed), and what concerns a whole input -- unreadable (``error``), without records (``error``, or
    ``note`` when allowed), a log's warnings such as a format that differs -- as tool execution notifications
    (``problems``: file, level, text)."""
    rules: dict[str, dict[str, object]] = {}
    for g in groups:
        if g.code not in rules:
            rules[g.code] = {
                "id": g.code,
                "name": g.first.rule,
                "shortDescription": {
                    "text": f"{message}: rule {g.first.rule} on {field_of(g.first.path) or 'the record'}"
                },
            }
    index = {code: i for i, code in enumerate(rules)}
    notifications = [
        {
            "level": level,
            "message": {"text": text},
            "locations": [{"physicalLocation": {"artifactLocation": {"uri": _uri(file)}}}],
        }
        for file, level, text in problems
    ]
    invocation: dict[str, object] = {"executionSuccessful": exit_code != 2, "exitCode": exit_code}
    if notifications:
        invocation["toolExecutionNotifications"] = notifications
    run: dict[str, object] = {
        "tool": {
            "driver": {
                "name": "battgen",
                "version": version,
                "rules": list(rules.values()),
            }
        },
        "invocations": [invocation],
        "results": [_result(g, index) for g in groups],
        "properties": {
            "message": message,
            "select": list(settings.select),
            "ignore": list(settings.ignore),
            "profile": settings.profile.name if settings.profile else None,
        },
    }
    return {"$schema": SARIF_SCHEMA, "version": "2.1.0", "runs": [run]}
