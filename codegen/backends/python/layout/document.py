"""The document a statement is laid out from: text, line breaks and groups that print flat when
they fit and break otherwise, as one flat list with start and end tags.

The model (and the printer in :mod:`.printer`) follows the one ruff's formatter prints, element
for element, so that a statement laid out here comes out as ``ruff format`` would write it: the
project checks ``generated/`` with ruff, but generating code must not need ruff.
"""

from __future__ import annotations

import enum
import itertools
from dataclasses import dataclass


class Mode(enum.Enum):
    FLAT = "flat"
    EXPANDED = "expanded"


class GroupMode(enum.Enum):
    FLAT = "flat"  # flat if it fits
    EXPAND = "expand"  # always expanded (asked for)
    PROPAGATED = "propagated"  # expanded because its content holds a hard line break


class Measure(enum.Enum):
    """How far a fitting test looks: up to the first line break, or every line of the content."""

    FIRST_LINE = "first line"
    ALL_LINES = "all lines"
    ALL_LINES_OVERFLOW = "all lines, text may overflow"


class Line(enum.Enum):
    SOFT = "soft"  # nothing when flat, a line break when expanded
    SOFT_OR_SPACE = "soft or space"  # a space when flat
    HARD = "hard"  # always a line break


class Kind(enum.Enum):
    GROUP = "group"
    CONDITIONAL_GROUP = "conditional group"
    INDENT = "indent"
    INDENT_IF_GROUP_BREAKS = "indent if group breaks"
    CONDITIONAL_CONTENT = "conditional content"
    FITS_EXPANDED = "fits expanded"
    BEST_FIT_PARENTHESIZE = "best fit parenthesize"
    ENTRY = "entry"  # one variant of a best-fitting choice


class ExpandParent:
    """Forces the enclosing group to expand (a magic trailing comma)."""


EXPAND_PARENT = ExpandParent()

_group_ids = itertools.count(1)


def new_group_id() -> int:
    return next(_group_ids)


@dataclass(frozen=True)
class Condition:
    """True when the group ``group_id`` (the enclosing one when None) prints in ``mode``."""

    mode: Mode
    group_id: int | None = None


@dataclass
class Start:
    kind: Kind
    group_id: int | None = None  # GROUP, INDENT_IF_GROUP_BREAKS, BEST_FIT_PARENTHESIZE
    mode: GroupMode = GroupMode.FLAT  # GROUP, CONDITIONAL_GROUP (mutated by propagate_expand)
    condition: Condition | None = None  # CONDITIONAL_GROUP, CONDITIONAL_CONTENT, FITS_EXPANDED
    propagate_expand: bool = False  # FITS_EXPANDED: its content holds a hard line break


@dataclass(frozen=True)
class End:
    kind: Kind


@dataclass(frozen=True)
class BestFitting:
    """The first variant that fits (each a list opened by an ENTRY tag); the last one otherwise."""

    variants: tuple[list[Element], ...]
    measure: Measure = Measure.FIRST_LINE


Element = str | Line | ExpandParent | BestFitting | Start | End
Content = Element | list[Element]


def flatten(*content: Content) -> list[Element]:
    """The elements of ``content``: single elements, and lists of elements (which builders give)."""
    out: list[Element] = []
    for item in content:
        if type(item) is list:
            out += item
        elif isinstance(item, str | Line | ExpandParent | BestFitting | Start | End):
            out.append(item)
        else:
            raise TypeError(f"not a document element: {item!r}")
    return out


def group(*content: Content, group_id: int | None = None, expand: bool = False) -> list[Element]:
    mode = GroupMode.EXPAND if expand else GroupMode.FLAT
    return [Start(Kind.GROUP, group_id=group_id, mode=mode), *flatten(*content), End(Kind.GROUP)]


def conditional_group(*content: Content, condition: Condition) -> list[Element]:
    start = Start(Kind.CONDITIONAL_GROUP, condition=condition)
    return [start, *flatten(*content), End(Kind.CONDITIONAL_GROUP)]


def indent(*content: Content) -> list[Element]:
    return [Start(Kind.INDENT), *flatten(*content), End(Kind.INDENT)]


def soft_block_indent(*content: Content) -> list[Element]:
    inner = flatten(*content)
    if not inner:
        return []
    return [Start(Kind.INDENT), Line.SOFT, *inner, End(Kind.INDENT), Line.SOFT]


def block_indent(*content: Content) -> list[Element]:
    inner = flatten(*content)
    if not inner:
        return []
    return [Start(Kind.INDENT), Line.HARD, *inner, End(Kind.INDENT), Line.HARD]


def if_group_breaks(*content: Content, group_id: int | None = None) -> list[Element]:
    start = Start(Kind.CONDITIONAL_CONTENT, condition=Condition(Mode.EXPANDED, group_id))
    return [start, *flatten(*content), End(Kind.CONDITIONAL_CONTENT)]


def if_group_fits_on_line(*content: Content, group_id: int | None = None) -> list[Element]:
    start = Start(Kind.CONDITIONAL_CONTENT, condition=Condition(Mode.FLAT, group_id))
    return [start, *flatten(*content), End(Kind.CONDITIONAL_CONTENT)]


def indent_if_group_breaks(*content: Content, group_id: int) -> list[Element]:
    start = Start(Kind.INDENT_IF_GROUP_BREAKS, group_id=group_id)
    return [start, *flatten(*content), End(Kind.INDENT_IF_GROUP_BREAKS)]


def fits_expanded(*content: Content, condition: Condition | None = None) -> list[Element]:
    start = Start(Kind.FITS_EXPANDED, condition=condition)
    return [start, *flatten(*content), End(Kind.FITS_EXPANDED)]


def best_fit_parenthesize(*content: Content, group_id: int | None) -> list[Element]:
    start = Start(Kind.BEST_FIT_PARENTHESIZE, group_id=group_id)
    return [start, *flatten(*content), End(Kind.BEST_FIT_PARENTHESIZE)]


def best_fitting(*variants: Content, measure: Measure = Measure.FIRST_LINE) -> BestFitting:
    entries = tuple([Start(Kind.ENTRY), *flatten(v), End(Kind.ENTRY)] for v in variants)
    return BestFitting(entries, measure)


def will_break(elements: list[Element]) -> bool:
    """Whether the content can only print expanded (a hard line break or a forced expansion)."""
    for element in elements:
        if element is Line.HARD or isinstance(element, ExpandParent):
            return True
        if isinstance(element, Start) and element.kind is Kind.GROUP and element.mode is not GroupMode.FLAT:
            return True
        if isinstance(element, BestFitting) and will_break(element.variants[0]):
            return True
    return False


def propagate_expand(elements: list[Element]) -> None:
    """Mark every group holding a hard line break (directly or through nested groups) expanded."""
    _propagate(elements, [])


def _expand_innermost(enclosing: list[tuple[str, Start | None, bool]]) -> None:
    if not enclosing:
        return
    what, tag, _ = enclosing[-1]
    if tag is None:
        return
    if what == "group" and tag.mode is GroupMode.FLAT:
        tag.mode = GroupMode.PROPAGATED
    elif what == "fits":
        tag.propagate_expand = True


def _propagate(elements: list[Element], enclosing: list[tuple[str, Start | None, bool]]) -> bool:
    expands = False
    for element in elements:
        element_expands = False
        if isinstance(element, Start):
            if element.kind in (Kind.GROUP, Kind.CONDITIONAL_GROUP):
                enclosing.append(("group", element, False))
            elif element.kind is Kind.BEST_FIT_PARENTHESIZE:
                enclosing.append(("best fit parenthesize", None, expands))
                expands = False
                continue
            elif element.kind is Kind.FITS_EXPANDED:
                enclosing.append(("fits", element, expands))
        elif isinstance(element, End):
            if element.kind in (Kind.GROUP, Kind.CONDITIONAL_GROUP):
                _, tag, _ = enclosing.pop()
                element_expands = tag is not None and tag.mode is not GroupMode.FLAT
            elif element.kind in (Kind.BEST_FIT_PARENTHESIZE, Kind.FITS_EXPANDED):
                _, _, expands = enclosing.pop()
                continue
        elif isinstance(element, BestFitting):
            enclosing.append(("best fitting", None, False))
            for variant in element.variants:
                _propagate(variant, enclosing)
            enclosing.pop()
            continue
        elif element is Line.HARD or isinstance(element, ExpandParent):
            element_expands = True
        if element_expands:
            expands = True
            _expand_innermost(enclosing)
    return expands
