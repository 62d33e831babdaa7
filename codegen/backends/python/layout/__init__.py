"""Lays generated Python source out the way ``ruff format`` would, without needing ruff.

Emitters write each statement on one line; :func:`format_module` breaks the ones that do not fit
(and normalises literals in all of them) with a document printer modelled on ruff's, so that
``generated/`` passes ``ruff format --check`` as generated. It lays out simple statements
(assignments, expressions, ``return``, ``raise``, ``from ... import``) and the headers of ``def``,
``if``/``elif``, ``while`` and ``for``; a statement with a comment or a string over several lines
in it, and the rest of the module (blank lines, docstrings, other headers), stay as written.

Modules: :mod:`.document` (what to print), :mod:`.printer`, :mod:`.fits` and :mod:`.state` (how
it is fitted to the line width), :mod:`.source` (what the AST forgets: parentheses, string parts,
spellings), :mod:`.context`, :mod:`.operators`, :mod:`.expressions` and :mod:`.statements`
(Python constructs as documents), :mod:`.module` (the entry point).
"""

from __future__ import annotations

from .module import LINE_LENGTH, format_module

__all__ = ["LINE_LENGTH", "format_module"]
