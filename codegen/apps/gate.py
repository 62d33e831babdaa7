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
YAML files in ``codegen/apps/profiles/``: each waiver names its message, the selector, the reason and
its evidence (upstream source and what real logs show).
"""

from __future__ import annotations

import fnmatch
import re
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from ..errors import BattgenError

PROFILES = Path(__file__).resolve().parent / "profiles"
CONFIG_KEYS = ("select", "ignore", "profile")
_INDEX = re.compile(r"\[\d+\]")
_CROSS = "cross-field:"


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
        raise BattgenError(f"unknown profile {name!r} (bundled profiles: {', '.join(profile_names())})")
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    waivers = tuple(
        Waiver(str(w["message"]), str(w["ignore"]), " ".join(str(w["reason"]).split()), tuple(w["evidence"]))
        for w in data["waivers"]
    )
    return Profile(str(data["name"]), str(data["doc"]), waivers)


@dataclass(frozen=True)
class Settings:
    """The selection in force and where it came from (``origin``: the pyproject.toml read, if any)."""

    select: tuple[str, ...] = ()
    ignore: tuple[str, ...] = ()
    profile: Profile | None = None
    origin: str | None = None


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
    chosen = load_profile(name) if name else None  # "" (--profile '') turns a configured profile off
    return Settings(chosen_select, chosen_ignore, chosen, where or None)


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
        yield f"profile {settings.profile.name}"
