"""Placeholder: the `battgen docs` command (issue 4)."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    del subparsers  # not available yet


def run(args: argparse.Namespace) -> int:
    del args
    return 2
