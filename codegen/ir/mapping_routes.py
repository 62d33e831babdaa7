"""How a converter between two endpoints is chained from mapping functions: the shortest route
through the graph of mapping directions under a policy (strict: through the concepts; px4 and
ardupilot: that firmware's own code paths), in mapping-name order. Every backend that writes
converters routes them here, so they chain the same functions."""

from __future__ import annotations

from collections import deque
from typing import Protocol, TypeVar

from .mappings import Mapping

POLICIES = ("strict", "px4", "ardupilot")
# the policies that restate a firmware's own code: after one, a chain reports losses only at its ends
FIRMWARE_POLICIES = ("px4", "ardupilot")
# ArduPilot has no uORB: a chain made only of steps inside a format (policy any: the uORB versions) is
# no ArduPilot behaviour, so its routes must take one of its own mappings (PX4 does run those steps)
_NEEDS_OWN_STEP = frozenset({"ardupilot"})


class MappingEdge(Protocol):
    """One direction of one mapping, as a backend holds it."""

    @property
    def source(self) -> str: ...
    @property
    def target(self) -> str: ...
    @property
    def function(self) -> str: ...  # "forward" / "backward"
    @property
    def mapping(self) -> Mapping: ...


E = TypeVar("E", bound=MappingEdge)


def policies_of(mapping: Mapping) -> frozenset[str]:
    return frozenset(POLICIES) if mapping.policy == "any" else frozenset({mapping.policy})


def route(edges: list[E], source: str, target: str, policy: str) -> list[E] | None:
    """The shortest chain of functions from ``source`` to ``target`` under ``policy``."""
    found = _shortest(edges, source, target, policy)
    if found is not None and policy in _NEEDS_OWN_STEP and all(e.mapping.policy != policy for e in found):
        return None
    return found


def _shortest(edges: list[E], source: str, target: str, policy: str) -> list[E] | None:
    usable = sorted((e for e in edges if policy in policies_of(e.mapping)), key=lambda e: (e.mapping.name, e.function))
    queue: deque[tuple[str, list[E]]] = deque([(source, [])])
    seen = {source}
    while queue:
        node, path = queue.popleft()
        if node == target:
            return path
        for e in usable:
            if e.source == node and e.target not in seen:
                seen.add(e.target)
                queue.append((e.target, [*path, e]))
    return None
