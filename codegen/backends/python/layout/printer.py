"""Prints a :mod:`.document` into text of a given line width.

A group prints flat when its content, and what follows it up to the next line break, fits in the
remaining width; otherwise its line breaks break. The queue of what is left to print and the
stack of enclosing modes work as in ruff's printer (whose results this must reproduce): a fitting
test (:mod:`.fits`) reads ahead through the same queue without consuming it (:mod:`.state`).
"""

from __future__ import annotations

from .document import (
    BestFitting,
    Condition,
    Element,
    End,
    ExpandParent,
    GroupMode,
    Kind,
    Line,
    Measure,
    Mode,
    Start,
    propagate_expand,
)
from .fits import FitsMeasurer
from .state import INDENT_WIDTH, Args, Queue, Stack, condition_mode, text_width


class Printer:
    def __init__(self, line_width: int) -> None:
        self.line_width_limit = line_width
        self.buffer: list[str] = []
        self.line_has_text = False
        self.line_width = 0
        self.pending_indent = 0
        self.measured_group_fits = False
        self.group_modes: dict[int, Mode] = {}

    def print(self, document: list[Element], indent: int) -> str:
        propagate_expand(document)
        self.pending_indent = indent
        stack: Stack = [(None, Args(indent=indent))]
        queue = Queue()
        queue.extend_back(document)
        while (element := queue.pop()) is not None:
            self.print_element(stack, queue, element)
        return "".join(self.buffer)

    # -- printing ---------------------------------------------------------------------------------

    def print_text(self, text: str) -> None:
        if self.pending_indent:
            self.buffer.append(" " * (INDENT_WIDTH * self.pending_indent))
            self.line_width += INDENT_WIDTH * self.pending_indent
            self.pending_indent = 0
        self.buffer.append(text)
        self.line_has_text = True
        self.line_width += text_width(text)

    def new_line(self) -> None:
        self.buffer.append("\n")
        self.line_width = 0
        self.line_has_text = False
        # fitting tests only looked up to the first line break: the next group measures again
        self.measured_group_fits = False

    def print_element(self, stack: Stack, queue: Queue, element: Element) -> None:
        args = stack[-1][1]
        if isinstance(element, str):
            self.print_text(element)
        elif isinstance(element, Line):
            if args.mode is Mode.FLAT and element is not Line.HARD:
                if element is Line.SOFT_OR_SPACE:
                    self.print_text(" ")
            else:
                if self.line_has_text:
                    self.new_line()
                self.pending_indent = args.indent
        elif isinstance(element, ExpandParent):
            pass
        elif isinstance(element, BestFitting):
            self.print_best_fitting(element, queue, stack)
        elif isinstance(element, Start):
            self.print_start(element, args, queue, stack)
        else:
            self.print_end(element, args, queue, stack)

    def print_start(self, tag: Start, args: Args, queue: Queue, stack: Stack) -> None:
        kind = tag.kind
        if kind is Kind.GROUP:
            if tag.mode is GroupMode.FLAT:
                mode = self.flat_group_print_mode(kind, tag.group_id, args, queue, stack)
            else:
                mode = Mode.EXPANDED
            if tag.group_id is not None:
                self.group_modes[tag.group_id] = mode
            stack.append((kind, args._replace(mode=mode)))
        elif kind is Kind.BEST_FIT_PARENTHESIZE:
            self.print_best_fit_parenthesize(tag, args, queue, stack)
        elif kind is Kind.CONDITIONAL_GROUP:
            assert tag.condition is not None
            if self.condition_mode(tag.condition, args) is tag.condition.mode:
                if tag.mode is GroupMode.FLAT:
                    mode = self.flat_group_print_mode(kind, None, args, queue, stack)
                else:
                    mode = Mode.EXPANDED
                stack.append((kind, args._replace(mode=mode)))
            else:
                stack.append((kind, args))
        elif kind is Kind.INDENT:
            stack.append((kind, args._replace(indent=args.indent + 1)))
        elif kind is Kind.CONDITIONAL_CONTENT:
            assert tag.condition is not None
            if self.condition_mode(tag.condition, args) is tag.condition.mode:
                stack.append((kind, args))
            else:
                queue.skip_content(kind)
        elif kind is Kind.INDENT_IF_GROUP_BREAKS:
            assert tag.group_id is not None
            expanded = self.group_modes[tag.group_id] is Mode.EXPANDED
            stack.append((kind, args._replace(indent=args.indent + 1) if expanded else args))
        elif kind is Kind.FITS_EXPANDED:
            if tag.condition is None or self.condition_mode(tag.condition, args) is tag.condition.mode:
                # the inner groups were measured expanded: they must measure again
                self.measured_group_fits = False
            stack.append((kind, args))
        else:
            stack.append((kind, args))

    def print_end(self, tag: End, args: Args, queue: Queue, stack: Stack) -> None:
        if tag.kind is Kind.BEST_FIT_PARENTHESIZE and args.mode is Mode.EXPANDED:
            popped, _ = stack.pop()
            assert popped is Kind.INDENT
            queue.extend_back([Line.HARD, ")"])
        popped, _ = stack.pop()
        assert popped is tag.kind, (popped, tag.kind)

    def condition_mode(self, condition: Condition, args: Args) -> Mode:
        return condition_mode(condition, args, self.group_modes)

    def flat_group_print_mode(self, kind: Kind, group_id: int | None, args: Args, queue: Queue, stack: Stack) -> Mode:
        if args.mode is Mode.FLAT and self.measured_group_fits:
            return Mode.FLAT  # an enclosing group already found that this one fits
        self.measured_group_fits = True
        if group_id is not None:
            self.group_modes[group_id] = Mode.FLAT
        stack.append((kind, args._replace(mode=Mode.FLAT)))
        fits = self.fits(queue, stack)
        stack.pop()
        return Mode.FLAT if fits else Mode.EXPANDED

    def print_best_fit_parenthesize(self, tag: Start, args: Args, queue: Queue, stack: Stack) -> None:
        opening: list[Element] = ["(", Start(Kind.INDENT), Line.HARD]
        if self.flat_group_print_mode(tag.kind, tag.group_id, args, queue, stack) is Mode.FLAT:
            mode = Mode.FLAT
        else:
            # parenthesize only if the content then fits; else rather break it without parentheses
            if tag.group_id is not None:
                self.group_modes[tag.group_id] = Mode.EXPANDED
            stack.append((tag.kind, args._replace(measure=Measure.ALL_LINES)))
            queue.extend_back(opening)
            fits_expanded = self.fits(queue, stack)
            queue.pop_slice()
            stack.pop()
            mode = Mode.EXPANDED if fits_expanded else Mode.FLAT
        if tag.group_id is not None:
            self.group_modes[tag.group_id] = mode
        if mode is Mode.EXPANDED:
            queue.extend_back(opening)
        stack.append((tag.kind, args._replace(mode=mode)))

    def print_best_fitting(self, element: BestFitting, queue: Queue, stack: Stack) -> None:
        args = stack[-1][1]
        variants = element.variants
        if args.mode is Mode.FLAT and self.measured_group_fits:
            queue.extend_back(variants[0])
            self.print_entry(queue, stack, args)
            return
        self.measured_group_fits = True
        for variant in variants[:-1]:
            content = variant[1:]  # the ENTRY start tag gets the measuring args below
            queue.extend_back(content)
            stack.append((Kind.ENTRY, args._replace(mode=Mode.FLAT, measure=element.measure)))
            fits = self.fits(queue, stack)
            stack.pop()
            queue.pop_slice()
            if fits:
                queue.extend_back(variant)
                self.print_entry(queue, stack, args._replace(mode=Mode.FLAT))
                return
        queue.extend_back(variants[-1])
        self.print_entry(queue, stack, args._replace(mode=Mode.EXPANDED))

    def print_entry(self, queue: Queue, stack: Stack, args: Args) -> None:
        start = queue.pop()
        assert isinstance(start, Start) and start.kind is Kind.ENTRY
        stack.append((Kind.ENTRY, args))
        depth = 1
        while (element := queue.pop()) is not None:
            if isinstance(element, Start) and element.kind is Kind.ENTRY:
                depth += 1
            elif isinstance(element, End) and element.kind is Kind.ENTRY:
                depth -= 1
                if depth == 0:
                    stack.pop()
                    return
            self.print_element(stack, queue, element)
        raise AssertionError("unterminated best-fitting entry")

    def fits(self, queue: Queue, stack: Stack) -> bool:
        measurer = FitsMeasurer(
            queue, stack, self.group_modes, self.line_width, self.pending_indent, self.line_width_limit
        )
        return measurer.fits()


def flat_text(document: list[Element]) -> str | None:
    """The document printed on one line, or None when something in it forces a line break.

    When the result fits the line width this is what :class:`Printer` prints too (every group
    then fits flat), so a statement short enough needs no fitting tests at all."""
    out: list[str] = []
    skipping = 0  # depth inside content shown only when a group breaks
    for element in document:
        if skipping:
            if isinstance(element, Start) and element.kind is Kind.CONDITIONAL_CONTENT:
                skipping += 1
            elif isinstance(element, End) and element.kind is Kind.CONDITIONAL_CONTENT:
                skipping -= 1
        elif type(element) is str:
            out.append(element)
        elif element is Line.SOFT_OR_SPACE:
            out.append(" ")
        elif element is Line.HARD or isinstance(element, ExpandParent):
            return None
        elif isinstance(element, BestFitting):
            inner = flat_text(element.variants[0][1:-1])
            if inner is None:
                return None
            out.append(inner)
        elif isinstance(element, Start):
            if element.kind is Kind.GROUP and element.mode is not GroupMode.FLAT:
                return None
            condition = element.condition
            if element.kind is Kind.CONDITIONAL_CONTENT and condition is not None and condition.mode is Mode.EXPANDED:
                skipping = 1
    return "".join(out)
