"""One parsed DSDL v0 definition: its attribute types, fields, constants and sections.

:mod:`.syntax` builds a :class:`TypeDef` per ``.uavcan`` file; composite types are held by full
name (:class:`RefT`), resolved to files by :mod:`.namespaces`. ``normalized`` spells each part as
the DSDL signature hashes it (see :mod:`.signature`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ...ir import FLOAT_MAX

# --------------------------------------------------------------------------------------------
# Types as written in a definition


@dataclass(frozen=True)
class PrimT:
    kind: str  # "bool" | "uint" | "int" | "float"
    bits: int
    cast: str  # "saturated" | "truncated"

    @property
    def normalized(self) -> str:
        return f"{self.cast} {'bool' if self.kind == 'bool' else f'{self.kind}{self.bits}'}"

    @property
    def value_range(self) -> tuple[int | float, int | float]:
        if self.kind == "float":
            return -FLOAT_MAX[self.bits], FLOAT_MAX[self.bits]
        if self.kind == "int":
            return -(1 << (self.bits - 1)), (1 << (self.bits - 1)) - 1
        return 0, (1 << self.bits) - 1


@dataclass(frozen=True)
class VoidT:
    bits: int

    @property
    def normalized(self) -> str:
        return f"void{self.bits}"


@dataclass(frozen=True)
class RefT:
    """A composite type, by full name (already resolved against the referencing namespace)."""

    full_name: str

    @property
    def normalized(self) -> str:
        return self.full_name


@dataclass(frozen=True)
class ArrayT:
    element: PrimT | RefT
    size: int  # maximum (dynamic) or exact (static) element count, after normalising [<N]
    dynamic: bool

    @property
    def normalized(self) -> str:
        return f"{self.element.normalized}[{'<=' if self.dynamic else ''}{self.size}]"


AttrT = PrimT | VoidT | RefT | ArrayT


# --------------------------------------------------------------------------------------------
# Definitions


@dataclass(frozen=True)
class FieldDef:
    name: str | None  # None for padding
    type: AttrT
    line: int
    above: str = ""  # the comment block directly above the line
    trailing: str = ""  # the comment at the end of the line

    @property
    def normalized(self) -> str:
        if isinstance(self.type, VoidT):
            return self.type.normalized
        return f"{self.type.normalized} {self.name}"


@dataclass(frozen=True)
class ConstDef:
    name: str
    type: PrimT
    value: int | float | bool
    line: int
    above: str = ""
    trailing: str = ""


@dataclass(frozen=True)
class Section:
    """A message body, or one half of a service."""

    fields: tuple[FieldDef, ...]
    constants: tuple[ConstDef, ...]
    union: bool
    line: int  # where the section starts: 1, or the line of '---'


@dataclass(frozen=True)
class TypeDef:
    full_name: str
    file: str  # display path
    default_id: int | None
    version: tuple[int, int] | None
    request: Section  # the message body for a message
    response: Section | None  # set for a service
    override_signature: int | None
    doc: str

    @property
    def is_service(self) -> bool:
        return self.response is not None

    @property
    def sections(self) -> tuple[Section, ...]:
        return (self.request,) if self.response is None else (self.request, self.response)

    @property
    def short_name(self) -> str:
        return self.full_name.rsplit(".", 1)[-1]
