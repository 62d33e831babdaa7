"""What ``convert --policy strict`` refuses: a record in which ``battgen validate`` finds an error, and nothing
else (issue 32). The verdict is validate's own (:mod:`..schemas.fits`: the generated ``validate()`` from the IR's
types, ranges, enums, bitmasks, sentinels and cross-field rules, read as validate reads it): a NaN where the
schema has another "unknown", an infinity, a value beyond its type or its range, an enum or bitmask value outside
its set. A log's record is judged as validate judges that log: fields the log lacks are
not its values, and its firmware's documented deviations (``gate/profiles/px4.yaml``: PX4 never sets
``max_error``) are waived, as validate waives them when nothing else is asked for (:func:`..gate.selection.
firmware_gate`). What validate's ``--select``, ``--ignore`` and ``[tool.battgen]`` choose is which findings a
project's CI reports, not what a value means: strict does not read them, so no project setting opens it to a value
no type holds.

Only a record with a violation pays for more than its ``validate()``: the gate and, for a log lacking fields,
the cross-field rules' fields (read from the bundled schemas' IR once per run) are looked up then.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

from ...errors import BattgenError
from ...inputs.records import Record


class StrictCheck:
    """Refuses, for one conversion's source side, each record validate would find an error in."""

    def __init__(self, kind: str | None, *, bundled: bool) -> None:
        self.kind = kind  # the input's kind (ulog, tlog, can, jsonl ...): whose firmware wrote it
        self.bundled = bundled  # the classes are the bundled package's: the bundled schemas' IR describes them
        self._gates: dict[str, Any] = {}

    def refuse(self, objs: Sequence[object], item: Record) -> None:
        """Raise a BattgenError naming the record and validate's first error, if any of ``objs`` has one."""
        for position, obj in enumerate(objs):
            check = getattr(obj, "validate", None)
            found = check() if callable(check) else ()
            if not found:
                continue
            from ..schemas.fits import errors  # only now: a clean record needs no gate

            name = str(getattr(obj, "QUALIFIED_NAME", ""))
            skip = item.skip if position == 0 else frozenset()  # what the log lacks is the record's own message's
            refused = errors(found, skip=skip, rules=functools.partial(self._rules, name), gate=self._gate(name))
            if refused:
                v = refused[0]
                message = str(v.message)
                if v.path and str(v.path) not in message:
                    message = f"{v.path}: {message}"
                where = f"{item.file}:{item.line}" if item.line > 0 else item.file
                raise BattgenError(f"{where}: record {item.index + 1}: cannot convert (--policy strict): {message}")

    def _gate(self, name: str) -> Any:
        gate = self._gates.get(name)
        if gate is None:
            from ..gate.selection import firmware_gate

            gate = self._gates[name] = firmware_gate(name, self.kind)
        return gate

    def _rules(self, name: str) -> dict[str, frozenset[str]]:
        return _rule_fields(name) if self.bundled and name else {}


@functools.cache
def _rule_fields(name: str) -> dict[str, frozenset[str]]:
    """The bundled schemas' cross-field rules of a message, each with the fields it reads (as validate has them)."""
    from ..schemas.fits import rule_fields
    from ..schemas.package import bundled_schemas, load_schemas

    schema = load_schemas(bundled_schemas())
    found = [m for m in schema.messages if m.qualified_name == name]
    return rule_fields(schema, found[0]) if found else {}
