"""The CI gate's options, one definition for ``validate`` and ``report``: ``--select``, ``--ignore`` and
``--profile``, read with ``[tool.battgen]`` of the nearest pyproject.toml
(:func:`codegen.apps.gate.selection.settings`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..apps.gate.selection import Settings, profile_names, settings


def add_gate_options(p: Any) -> None:
    """``--select``, ``--ignore``, ``--profile`` on a sub-command's parser."""
    p.add_argument(
        "--select",
        action="append",
        metavar="SELECTORS",
        help="report only these findings: RULE/FIELD, RULE or FIELD, wildcards allowed, comma-separated; a name "
        "that is no rule or field of the message is an error (replaces [tool.battgen] select)",
    )
    p.add_argument(
        "--ignore",
        action="append",
        metavar="SELECTORS",
        help="leave these findings out (counted in the summary; replaces [tool.battgen] ignore)",
    )
    p.add_argument(
        "--profile",
        metavar="NAME",
        help=f"waive a bundled profile's known firmware deviations ({', '.join(profile_names())}); default: the "
        "profile of the log's firmware, if one is bundled; '' for none",
    )


def _selectors(values: list[str] | None) -> list[str] | None:
    """--select/--ignore values: repeatable, each comma-separated; None when not given."""
    if values is None:
        return None
    return [s.strip() for v in values for s in v.split(",") if s.strip()]


def gate_settings(args: argparse.Namespace) -> Settings:
    """The selection the command line and [tool.battgen] give (a BattgenError for an unknown profile)."""
    return settings(_selectors(args.select), _selectors(args.ignore), args.profile, Path.cwd())


def firmware_note(source: str, chosen: Settings) -> str | None:
    """The stderr note when the log's firmware chose the profile (None when it did not)."""
    if chosen.profile is None or not chosen.profile_from:
        return None
    return f"{source}: note: profile {chosen.profile.name}, as {chosen.profile_from} (--profile '' for none)"
