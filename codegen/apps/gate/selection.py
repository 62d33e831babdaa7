"""Which findings ``battgen validate`` reports: rule selection as linters do it, and profiles of known
firmware deviations.

A finding's *code* is ``RULE/FIELD``: the validator's rule (``range``, ``nan``, ``enum``,
``cross-field:cells-beyond-count-zero`` ...) and the field path without array indexes
(``voltage_cell_v[3]`` -> ``voltage_cell_v``). A selector is a code, a rule alone, or a field alone,
with ``*`` and ``?`` wildcards: ``range/max_error``, ``range``, ``max_error``, ``cells-beyond-count-zero``
(a cross-field rule by its id), ``range/*``. A finding is reported when it matches ``select`` (every
finding when ``select`` is empty) and matches no ``ignore`` selector and no waiver of the profile.

Settings come from ``[tool.battgen]`` in the nearest ``pyproject.toml`` from the working folder upward
(``select``, ``ignore``: lists of selectors; ``profile``: a bundled profile's name), and from the
command line, whose ``--select``, ``--ignore`` and ``--profile`` replace the file's. Profiles are
YAML files in ``codegen/apps/gate/profiles/``: each waiver names its message, the selector, the reason and
its evidence (upstream source and what real logs show). Without a profile from either, a log's firmware
chooses it (:func:`for_firmware`: a PX4 log is judged by what PX4 writes); ``--profile ''`` turns that off.

A gate that a typo could open is no gate: every selector must name a rule or a field of the message checked
(a wildcard must match one), else :func:`check_selectors` refuses it with the closest names, as an unknown
profile is refused.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import re
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import BattgenError, close_names
from ...ir import Message

PROFILES = Path(__file__).resolve().parent / "profiles"
CONFIG_KEYS = ("select", "ignore", "profile")
_INDEX = re.compile(r"\[\d+\]")
_CROSS = "cross-field:"
# The rules of the generated validators (generated/_validate.py: a Violation's rule), and the validate app's own
# ("internal": the validator failed); tests/cli/test_gate_names.py reads the generated module to keep this in step.
GENERIC_RULES = (
    "type",
    "type-bounds",
    "nan",
    "range",
    "enum",
    "bitmask",
    "pattern",
    "length",
    "required",
    "union",
    "internal",
)
FAILSAFE_RULE = "cross-field:failsafe"  # the validate app's failsafe checks of a parameter set


def closest(name: str, known: Iterable[str]) -> str:
    """`` (did you mean a, b?)`` with the known names closest to ``name`` (:func:`close_names`, as every other
    "did you mean"); "" when none is close."""
    close = close_names(name, known)
    return f" (did you mean {', '.join(close)}?)" if close else ""


def unknown_name(what: str, name: str, known: Iterable[str]) -> BattgenError:
    """The error for a name an option does not know: the closest known names, else all of them (up to 12)."""
    names = sorted(set(known))
    hint = closest(name, names)
    if not hint:
        shown = ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")
        hint = f" (known: {shown})"
    return BattgenError(f"unknown {what} {name!r}{hint}")


def field_of(path: str) -> str:
    """A finding's field: its path without array indexes (``cells[3].v`` -> ``cells.v``)."""
    return _INDEX.sub("", path)


def finding_code(rule: str, path: str) -> str:
    """``RULE/FIELD``, or the rule alone for a finding about the whole record."""
    name = field_of(path)
    return f"{rule}/{name}" if name else rule


def matches(selector: str, rule: str, path: str) -> bool:
    """Whether a selector (``RULE/FIELD``, ``RULE`` or ``FIELD``, with wildcards) covers a finding."""
    name = field_of(path)
    rules = (rule, rule[len(_CROSS) :]) if rule.startswith(_CROSS) else (rule,)
    if "/" in selector:
        want_rule, _, want_field = selector.partition("/")
        return any(fnmatch.fnmatchcase(r, want_rule) for r in rules) and fnmatch.fnmatchcase(name, want_field)
    return any(fnmatch.fnmatchcase(r, selector) for r in rules) or fnmatch.fnmatchcase(name, selector)


@dataclass(frozen=True)
class Waiver:
    """One known deviation of a profile: the message, the selector it waives, why, and the evidence."""

    message: str
    selector: str
    reason: str
    evidence: tuple[str, ...]


@dataclass(frozen=True)
class Profile:
    name: str
    doc: str
    waivers: tuple[Waiver, ...]


def profile_names() -> list[str]:
    return sorted(p.stem for p in PROFILES.glob("*.yaml"))


def load_profile(name: str) -> Profile:
    """A bundled profile by name; BattgenError naming the known ones otherwise."""
    path = PROFILES / f"{name}.yaml"
    if not re.fullmatch(r"[a-z0-9_-]+", name) or not path.is_file():
        hint = closest(name, profile_names())
        raise BattgenError(f"unknown profile {name!r}{hint} (bundled profiles: {', '.join(profile_names())})")
    import yaml  # here: a run without --profile reads no YAML

    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    waivers = tuple(
        Waiver(str(w["message"]), str(w["ignore"]), " ".join(str(w["reason"]).split()), tuple(w["evidence"]))
        for w in data["waivers"]
    )
    return Profile(str(data["name"]), str(data["doc"]), waivers)


@dataclass(frozen=True)
class Settings:
    """The selection in force and where it came from (``origin``: the pyproject.toml read, if any; ``where``: per
    key, the option or file that gave it, for errors; ``profile_given``: whether a profile was asked for at all,
    ``--profile ''`` included, so that the log's firmware does not choose one; ``profile_from``: "" when asked for,
    else why the profile applies)."""

    select: tuple[str, ...] = ()
    ignore: tuple[str, ...] = ()
    profile: Profile | None = None
    origin: str | None = None
    where: Mapping[str, str] = field(default_factory=dict)
    profile_given: bool = False
    profile_from: str = ""


def find_config(start: Path) -> Path | None:
    """The nearest pyproject.toml with a [tool.battgen] table, from ``start`` upward."""
    for folder in (start, *start.parents):
        candidate = folder / "pyproject.toml"
        if candidate.is_file():
            try:
                data = tomllib.loads(candidate.read_text(encoding="utf-8"))
            except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
                raise BattgenError(f"{candidate}: cannot read: {exc}") from None
            if isinstance(data.get("tool"), dict) and "battgen" in data["tool"]:
                return candidate
    return None


def _selectors(value: object, where: str, key: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v.strip() for v in value):
        raise BattgenError(f"{where}: [tool.battgen] {key}: expected a list of selectors (strings)")
    return tuple(v.strip() for v in value)


def read_config(path: Path) -> Mapping[str, object]:
    """[tool.battgen] of a pyproject.toml, its keys checked."""
    table = tomllib.loads(path.read_text(encoding="utf-8"))["tool"]["battgen"]
    if not isinstance(table, dict):
        raise BattgenError(f"{path}: [tool.battgen]: expected a table")
    unknown = sorted(set(table) - set(CONFIG_KEYS))
    if unknown:
        raise BattgenError(f"{path}: [tool.battgen]: unknown key {unknown[0]!r} (expected {', '.join(CONFIG_KEYS)})")
    return table


def settings(select: Sequence[str] | None, ignore: Sequence[str] | None, profile: str | None, cwd: Path) -> Settings:
    """The selection: the command line's values where given, else [tool.battgen]'s, else none."""
    config_path = find_config(cwd)
    table: Mapping[str, object] = read_config(config_path) if config_path is not None else {}
    where = config_path.as_posix() if config_path is not None else ""
    chosen_select = tuple(select) if select is not None else _selectors(table.get("select", []), where, "select")
    chosen_ignore = tuple(ignore) if ignore is not None else _selectors(table.get("ignore", []), where, "ignore")
    name = profile if profile is not None else table.get("profile")
    if name is not None and not isinstance(name, str):
        raise BattgenError(f"{where}: [tool.battgen] profile: expected a profile name")
    origins = {
        key: f"--{key}" if given is not None else f"{where}: [tool.battgen] {key}"
        for key, given in (("select", select), ("ignore", ignore), ("profile", profile))
    }
    try:
        chosen = load_profile(name) if name else None  # "" (--profile '') turns a configured profile off
    except BattgenError as exc:
        raise BattgenError(f"{origins['profile']}: {exc}") from None
    return Settings(chosen_select, chosen_ignore, chosen, where or None, origins, name is not None)


# The firmware a log kind is written by, where the kind alone tells it (a ULog is PX4's format, DataFlash
# ArduPilot's); the report reads a log's own context (LogContext.autopilot), which says the same for these.
KIND_FIRMWARE = {"ulog": "px4", "dataflash": "ardupilot"}


def for_firmware(chosen: Settings, autopilot: str | None, firmware: str | None = None) -> Settings:
    """The settings for a log of this firmware family (``px4``, ``ardupilot``): its bundled profile when none was
    asked for, with where that came from; else the settings as they are."""
    if chosen.profile_given or autopilot is None or autopilot not in profile_names():
        return chosen
    why = f"the log's firmware is {firmware or autopilot}"
    return dataclasses.replace(chosen, profile=load_profile(autopilot), profile_from=why)


def firmware_gate(message: str, kind: str | None) -> Gate:
    """Validate's gate for a file of this kind when nothing is asked for: the bundled profile of the firmware
    that writes such files (a ULog: PX4's), else none (``convert --policy strict`` judges records by it)."""
    return Gate(for_firmware(Settings(), KIND_FIRMWARE.get(kind) if kind is not None else None), message)


@dataclass(frozen=True)
class Names:
    """What a selector may name for one message: its rules (cross-field ones by their full and short names) and
    its fields (``patterns``: devicetree properties named by a regular expression)."""

    message: str
    rules: frozenset[str]
    fields: frozenset[str]
    patterns: tuple[str, ...] = ()

    def rule_known(self, selector: str) -> bool:
        return any(fnmatch.fnmatchcase(r, selector) for r in self.rules)

    def field_known(self, selector: str) -> bool:
        """A field, or a member of one (``timestamp.usec``: its field is ``timestamp``)."""
        head = selector.split(".", 1)[0]
        if any(fnmatch.fnmatchcase(f, head) for f in self.fields):
            return True
        return any(re.fullmatch(p, head) for p in self.patterns if not any(c in head for c in "*?["))


def names_of(message: Message, rule_ids: Iterable[str], failsafe: bool = False) -> Names:
    """The names of one message: the generic rules, its cross-field rules (``rule_ids``, as the checker has
    them), the failsafe rule where the validate app runs it, and its fields."""
    cross = [*(_CROSS + r for r in rule_ids), *([FAILSAFE_RULE] if failsafe else [])]
    rules = frozenset((*GENERIC_RULES, *cross, *(c[len(_CROSS) :] for c in cross)))
    fields = frozenset(f.name for f in message.fields if f.pattern is None)
    patterns = tuple(f.pattern for f in message.fields if f.pattern is not None)
    return Names(message.qualified_name, rules, fields, patterns)


def unknown_selector(selector: str, names: Names) -> str | None:
    """Why a selector names nothing of the message (None when it names something)."""
    if "/" in selector:
        rule, _, name = selector.partition("/")
        if not names.rule_known(rule):
            return f"no rule of {names.message} is called {rule!r}{closest(rule, names.rules)}"
        if not names.field_known(name):
            return f"{names.message} has no field {name!r}{closest(name, names.fields)}"
        return None
    if names.rule_known(selector) or names.field_known(selector):
        return None
    hint = closest(selector, names.rules | names.fields)
    return f"no rule or field of {names.message} is called {selector!r}{hint}"


def check_selectors(chosen: Settings, names: Names) -> None:
    """Refuse a selector that names no rule or field of the message: a misspelt ``--select`` would leave every
    finding out, a misspelt ``--ignore`` would look as if it had worked."""
    for key, selectors in (("select", chosen.select), ("ignore", chosen.ignore)):
        for s in selectors:
            problem = unknown_selector(s, names)
            if problem is not None:
                raise BattgenError(f"{chosen.where.get(key, '--' + key)}: {problem}")


@dataclass
class Gate:
    """Decides per finding: reported, or why not (the selector or waiver that left it out)."""

    settings: Settings
    message: str  # the qualified name of the message checked
    waived: dict[str, int] = field(default_factory=dict)  # reason text -> findings left out

    def __post_init__(self) -> None:
        profile = self.settings.profile
        self.waivers = [w for w in (profile.waivers if profile else ()) if w.message == self.message]

    def why_not(self, rule: str, path: str) -> str | None:
        """None when the finding is reported; else a short reason (``--ignore range``, ``profile px4: ...``)."""
        select = self.settings.select
        if select and not any(matches(s, rule, path) for s in select):
            return "not selected"
        for s in self.settings.ignore:
            if matches(s, rule, path):
                return f"ignored ({s})"
        for w in self.waivers:
            if matches(w.selector, rule, path):
                name = self.settings.profile.name if self.settings.profile else ""
                return f"profile {name}: {w.selector}: {w.reason}"
        return None


def describe(settings: Settings) -> Iterable[str]:
    """The selection in force, in words (for the text summary)."""
    if settings.select:
        yield "select " + ", ".join(settings.select)
    if settings.ignore:
        yield "ignore " + ", ".join(settings.ignore)
    if settings.profile is not None:
        yield f"profile {settings.profile.name}" + (f" (as {settings.profile_from})" if settings.profile_from else "")
