"""Lays generated Python source out the way ``ruff format`` would, without needing ruff.

Emitters write each statement on one line; :func:`format_module` breaks the ones that do not fit
(and normalises literals in all of them) with a document printer modelled on ruff's, so that
``generated/`` passes ``ruff format --check`` as generated. Statements that already span lines
(hand-laid-out template code) and lines with comments are kept as written.
"""

from __future__ import annotations

from .module import LINE_LENGTH, format_module

__all__ = ["LINE_LENGTH", "format_module"]
