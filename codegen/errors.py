"""Errors a user sees: each names where the problem is and what was expected."""

from __future__ import annotations


class BattgenError(Exception):
    """Base of every error battgen reports to a user (the CLI prints it without a traceback)."""


class LocatedError(BattgenError):
    """A problem at a place in an input file: names the file, the 1-based line (0: the whole file)
    and what was expected."""

    def __init__(self, file: str, line: int, message: str) -> None:
        super().__init__(f"{file}:{line}: {message}")
        self.file = file
        self.line = line
        self.message = message


class SchemaError(LocatedError):
    """A malformed schema."""
