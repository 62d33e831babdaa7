"""Errors a user sees: each names where the problem is and what was expected."""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from difflib import get_close_matches


class BattgenError(Exception):
    """Base of every error battgen reports to a user (the CLI prints it without a traceback)."""


class LocatedError(BattgenError):
    """A problem at a place in an input file: names the file, the 1-based line (0: the whole file, printed
    without a line, never as a fake ``file:0:``) and what was expected."""

    def __init__(self, file: str, line: int, message: str) -> None:
        super().__init__(f"{place(file, line)}: {message}")
        self.file = file
        self.line = line
        self.message = message


def place(file: str, line: int) -> str:
    """``file:line``, or the file alone where the problem has no line (0: the whole file, a .dtb, a log)."""
    return f"{file}:{line}" if line > 0 else file


def cannot_read(exc: OSError) -> str:
    """The one wording of a file that cannot be opened, whichever command and reader met it:
    ``cannot read file: no such file or directory``."""
    return f"cannot read file: {(exc.strerror or str(exc)).lower()}"


def missing_file(name: str) -> BattgenError:
    """A named input that does not exist, checked before a command starts, in :func:`cannot_read`'s words."""
    return BattgenError(f"{name}: {cannot_read(FileNotFoundError(2, 'No such file or directory'))}")


def close_names(name: str, known: Iterable[str]) -> list[str]:
    """The (up to three) known names closest to ``name``, case ignored; where none is close, the names whose last
    dotted part is close to ``name``'s (a short form typed with the wrong prefix). Every "did you mean" of battgen
    is made from this list."""
    names = sorted(set(known))
    folded = {n.casefold(): n for n in names}
    close = get_close_matches(name.casefold(), list(folded), n=3, cutoff=0.6)
    if close:
        return [folded[c] for c in close]
    tails = {n.rsplit(".", 1)[-1].casefold(): n for n in names}
    return [tails[t] for t in get_close_matches(name.rsplit(".", 1)[-1].casefold(), list(tails), n=3)]


def did_you_mean(name: str, known: Iterable[str], *, what: str = "names") -> str:
    """The end of an unknown-name error: the few known names closest to ``name`` (:func:`close_names`), else how
    many names there are, never the whole list (a package knows thousands of messages)."""
    names = sorted(set(known))  # once: ``known`` may be a generator, and both steps read it
    close = close_names(name, names)
    if close:
        return f"did you mean {' or '.join(map(repr, close))}?"
    return f"known {what}: {', '.join(names)}" if len(names) <= 16 else f"{len(names)} {what} known"


class OutputError(BattgenError):
    """An output that cannot be written (a full disk, a folder that is a file): the run stops, whatever its
    inputs; nothing half-written is left visible."""

    @classmethod
    def of(cls, path: object, exc: OSError) -> OutputError:
        return cls(f"{path}: cannot write: {exc.strerror or exc}")


class SchemaError(LocatedError):
    """A malformed schema."""


class ErrorList(BattgenError):
    """Every problem found in one run (several files, several lines of one file), like a compiler's
    report: ``errors`` in the order found, one ``file:line: ...`` line each."""

    def __init__(self, errors: Sequence[BattgenError]) -> None:
        flat: dict[str, BattgenError] = {}  # one report per problem, though two paths may find it
        for error in errors:
            for one in error.errors if isinstance(error, ErrorList) else (error,):
                flat.setdefault(str(one), one)
        self.errors: tuple[BattgenError, ...] = tuple(flat.values())
        count = len(self.errors)
        summary = f"{count} error{'s' if count != 1 else ''}"
        super().__init__("\n".join([*(str(e) for e in self.errors), summary]) if count != 1 else str(self.errors[0]))

    @staticmethod
    def raise_if_any(errors: Sequence[BattgenError]) -> None:
        """Raise the one error as itself, several as an ErrorList; nothing when the list is empty."""
        if len(errors) == 1 and not isinstance(errors[0], ErrorList):
            raise errors[0]
        if errors:
            raise ErrorList(errors)


class ErrorCollector:
    """Collects the errors of independent steps (one per file, say) so that a run reports them all::

    found = ErrorCollector()
    for path in paths:
        with found.step():
            parse(path)
    found.raise_if_any()
    """

    def __init__(self) -> None:
        self.errors: list[BattgenError] = []

    @contextmanager
    def step(self) -> Iterator[None]:
        try:
            yield
        except BattgenError as error:
            self.errors.append(error)

    def raise_if_any(self) -> None:
        ErrorList.raise_if_any(self.errors)
