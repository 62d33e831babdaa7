"""The CI gate in a report: the findings ``validate`` would report of an input, by the same settings.

``--select``, ``--ignore``, ``--profile`` and ``[tool.battgen]`` are read as ``validate`` reads them
(:func:`codegen.apps.gate.selection.settings`); an unknown name is refused the same way
(:func:`~codegen.apps.gate.selection.check_selectors`, against the input's checked message), and without a profile
asked for, the log's firmware chooses one (:func:`~codegen.apps.gate.selection.for_firmware`, from the log's own
context). What is left out is counted per reason and said on the page, never dropped silently.
"""

from __future__ import annotations

from ..gate.selection import Gate, Settings, check_selectors, for_firmware
from .series import InputSeries


def apply_gate(item: InputSeries, chosen: Settings) -> None:
    """Keep the findings the gate reports in ``item.findings``; count the rest in ``item.left_out``."""
    context = item.context
    own = for_firmware(chosen, context.autopilot, context.firmware) if context is not None else chosen
    item.gate = own
    if item.names is None:  # no message schema (a DataFlash log): nothing was checked, nothing to name
        return
    check_selectors(own, item.names)
    gate = Gate(own, item.names.message)
    kept = []
    for group in item.findings:
        reason = gate.why_not(group.rule, group.path)
        if reason is None:
            kept.append(group)
        else:
            short = ": ".join(reason.split(": ")[:2])  # "profile px4: range/max_error", as validate's summary
            item.left_out[short] = item.left_out.get(short, 0) + group.count
    item.findings = kept
