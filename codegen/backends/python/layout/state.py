"""The printer's working state that fitting tests share: what is left to print (a queue that a
test reads ahead in without consuming it), the stack of modes of the open tags, text widths."""

from __future__ import annotations

import unicodedata
from typing import NamedTuple

from .document import Condition, Element, End, Kind, Measure, Mode, Start

INDENT_WIDTH = 4


class Args(NamedTuple):
    """How the content of the innermost open tag prints: indentation level, mode, measure."""

    indent: int = 0
    mode: Mode = Mode.EXPANDED
    measure: Measure = Measure.FIRST_LINE


def text_width(text: str) -> int:
    if text.isascii():
        return len(text)
    return sum(2 if unicodedata.east_asian_width(c) in "WF" else 1 for c in text)


class Queue:
    """What is left to print: a stack of element lists, each with the index of its next element."""

    def __init__(self, items: list[list[Element]] | None = None, indexes: list[int] | None = None) -> None:
        self.items: list[list[Element]] = items if items is not None else []
        self.indexes: list[int] = indexes if indexes is not None else []

    def copy(self) -> Queue:
        return Queue(list(self.items), list(self.indexes))

    def pop(self) -> Element | None:
        items, indexes = self.items, self.indexes
        while items:
            top = items[-1]
            index = indexes[-1]
            if index < len(top):
                indexes[-1] = index + 1
                return top[index]
            items.pop()
            indexes.pop()
        return None

    def extend_back(self, elements: list[Element]) -> None:
        if elements:
            self.items.append(elements)
            self.indexes.append(0)

    def pop_slice(self) -> None:
        self.items.pop()
        self.indexes.pop()

    def skip_content(self, kind: Kind) -> None:
        depth = 1
        while (element := self.pop()) is not None:
            if isinstance(element, Start) and element.kind is kind:
                depth += 1
            elif isinstance(element, End) and element.kind is kind:
                depth -= 1
                if depth == 0:
                    return


Stack = list[tuple[Kind | None, Args]]


def condition_mode(condition: Condition, args: Args, group_modes: dict[int, Mode]) -> Mode:
    """The mode a condition tests: its group's, or the enclosing one's."""
    return args.mode if condition.group_id is None else group_modes[condition.group_id]
