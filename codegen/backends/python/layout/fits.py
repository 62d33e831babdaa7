"""Whether what is left to print fits the line width: the test the printer makes before printing
a group flat, reading ahead through the queue in the modes of the enclosing tags."""

from __future__ import annotations

import enum

from .document import BestFitting, Element, End, ExpandParent, GroupMode, Kind, Line, Measure, Mode, Start
from .state import INDENT_WIDTH, Args, Queue, Stack, condition_mode, text_width


class _Fits(enum.Enum):
    YES = "yes"
    NO = "no"
    MAYBE = "maybe"


class FitsMeasurer:
    """Reads ahead from the printer's position, in the modes the stack says, without printing."""

    def __init__(
        self, queue: Queue, stack: Stack, group_modes: dict[int, Mode], line_width: int, pending_indent: int, limit: int
    ) -> None:
        self.group_modes = group_modes  # shared with the printer: a test records the modes it assumes
        self.queue = queue.copy()
        self.stack: Stack = list(stack)
        self.pending_indent = pending_indent
        self.line_width = line_width
        self.limit = limit

    def fits(self) -> bool:
        pop, stack, limit = self.queue.pop, self.stack, self.limit
        while (element := pop()) is not None:
            if type(element) is str:  # most elements are text: measured here, not in fits_element
                if self.pending_indent:
                    self.line_width += INDENT_WIDTH * self.pending_indent
                    self.pending_indent = 0
                self.line_width += len(element) if element.isascii() else text_width(element)
                if self.line_width > limit and stack[-1][1].measure is not Measure.ALL_LINES_OVERFLOW:
                    return False
                continue
            result = self.fits_element(element)
            if result is _Fits.YES:
                return True
            if result is _Fits.NO:
                return False
        return True

    def fits_element(self, element: Element) -> _Fits:
        args = self.stack[-1][1]
        if isinstance(element, str):
            return self.fits_text(element, args)
        if isinstance(element, Line):
            if args.mode is Mode.FLAT:
                if element is Line.SOFT_OR_SPACE:
                    return self.fits_text(" ", args)
                if element is Line.HARD:
                    return _Fits.YES
            elif args.measure is Measure.FIRST_LINE:
                return _Fits.YES
            else:
                self.line_width = 0
                self.pending_indent = args.indent
            return _Fits.MAYBE
        if isinstance(element, ExpandParent):
            return _Fits.MAYBE
        if isinstance(element, BestFitting):
            if args.mode is Mode.FLAT:
                variant, entry_args = element.variants[0], args._replace(measure=element.measure)
            else:
                variant, entry_args = element.variants[-1], args
            self.stack.append((Kind.ENTRY, entry_args))
            self.queue.extend_back(variant[1:])
            return _Fits.MAYBE
        if isinstance(element, End):
            return self.fits_end(element, args)
        return self.fits_start(element, args)

    def fits_start(self, tag: Start, args: Args) -> _Fits:
        kind = tag.kind
        modes = self.group_modes
        if kind is Kind.INDENT:
            self.stack.append((kind, args._replace(indent=args.indent + 1)))
        elif kind is Kind.GROUP:
            return self.fits_group(kind, tag.mode, tag.group_id, args)
        elif kind is Kind.BEST_FIT_PARENTHESIZE:
            if tag.group_id is not None:
                modes[tag.group_id] = args.mode
            self.stack.append((kind, args))
        elif kind is Kind.CONDITIONAL_GROUP:
            assert tag.condition is not None
            if condition_mode(tag.condition, args, self.group_modes) is tag.condition.mode:
                return self.fits_group(kind, tag.mode, None, args)
            self.stack.append((kind, args))
        elif kind is Kind.CONDITIONAL_CONTENT:
            assert tag.condition is not None
            if condition_mode(tag.condition, args, self.group_modes) is tag.condition.mode:
                self.stack.append((kind, args))
            else:
                self.queue.skip_content(kind)
        elif kind is Kind.INDENT_IF_GROUP_BREAKS:
            assert tag.group_id is not None
            expanded = modes[tag.group_id] is Mode.EXPANDED
            self.stack.append((kind, args._replace(indent=args.indent + 1) if expanded else args))
        elif kind is Kind.FITS_EXPANDED:
            met = tag.condition is None or condition_mode(tag.condition, args, self.group_modes) is tag.condition.mode
            if args.mode is Mode.FLAT and met:
                # measure the content fully expanded; only what comes before and after must fit
                self.stack.append((kind, args._replace(measure=Measure.ALL_LINES_OVERFLOW, mode=Mode.EXPANDED)))
            elif args.mode is Mode.FLAT and tag.propagate_expand:
                return _Fits.NO
            else:
                self.stack.append((kind, args))
        else:
            self.stack.append((kind, args))
        return _Fits.MAYBE

    def fits_end(self, tag: End, args: Args) -> _Fits:
        if tag.kind is Kind.BEST_FIT_PARENTHESIZE and args.mode is Mode.EXPANDED and self.stack[-1][0] is Kind.INDENT:
            self.stack.pop()
            _, unindented = self.stack.pop()
            self.line_width = 0
            self.pending_indent = unindented.indent
            return self.fits_text(")", unindented)
        self.stack.pop()
        return _Fits.MAYBE

    def fits_group(self, kind: Kind, group_mode: GroupMode, group_id: int | None, args: Args) -> _Fits:
        mode = args.mode if group_mode is GroupMode.FLAT else Mode.EXPANDED
        self.stack.append((kind, args._replace(mode=mode)))
        if group_id is not None:
            self.group_modes[group_id] = mode
        return _Fits.MAYBE

    def fits_text(self, text: str, args: Args) -> _Fits:
        self.line_width += INDENT_WIDTH * self.pending_indent
        self.pending_indent = 0
        self.line_width += text_width(text)
        if self.line_width > self.limit and args.measure is not Measure.ALL_LINES_OVERFLOW:
            return _Fits.NO
        return _Fits.MAYBE
