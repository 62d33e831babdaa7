"""DroneCAN (UAVCAN v0) codec: bit-exact ``encode``/``decode`` generated per data type.

Every DroneCAN class gets ``encode(*, tao=True) -> bytes``, ``decode(data, *, tao=True)``,
``DATA_TYPE_ID`` / ``DATA_TYPE_SIGNATURE`` class attributes and, for a ``@union``, a
``union_field`` attribute naming the held branch, kept by the runtime's ``Union`` (branch
attributes are None except the held one; assigning a branch selects it, as in pydronecan).
The shared runtime (``_dronecan.py``) holds float16 rounding (``float32_bits`` and the cuts off the
common path), the dynamic uint8 arrays (``put_bytes``, ``get_bytes``), the bit-stream finisher and
reader (``finish``, ``read``), ``DecodeError`` and ``transfer_crc``.
Layout planning lives in :mod:`.plan`, code emission in :mod:`.emit`.
"""

from __future__ import annotations

from .....ir import CompositeType, Message, Schema, SourceFormat
from ...extensions import Contribution
from ...field_source import FieldBuilder
from ...literals import py_literal
from ...module_context import ModuleContext
from ...runtime import copied
from ...views import ClassView
from .emit import MessageEmitter
from .field_map import field_map
from .plan import Planner


class _Factories(dict[str, str]):
    """Qualified name -> expression giving the class, registering a factory on first use."""

    def __init__(self, ctx: ModuleContext) -> None:
        super().__init__()
        self.ctx = ctx

    def __missing__(self, name: str) -> str:
        ref = self.ctx.classes[name]
        value = self.ctx.factory(ref) + "()"
        self[name] = value
        return value


def _free_name(name: str, taken: set[str]) -> str:
    while name in taken:
        name += "_"
    return name


class _Codec:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        info = msg.dronecan
        if msg.format is not SourceFormat.DRONECAN or info is None:
            return Contribution()
        factories = _Factories(ctx)
        planner = Planner(ctx.schema, factories)
        for f in msg.fields:  # fail early, with the field named, on a dangling reference
            if isinstance(f.type, CompositeType):
                ctx.composite(f.type, f)
        emitter = MessageEmitter(planner, msg, view.name, ctx, factories)
        taken = {f.ident for f in view.fields} | {c[0] for c in view.constants} | {"QUALIFIED_NAME"}
        id_name = _free_name("DATA_TYPE_ID", taken)
        sig_name = _free_name("DATA_TYPE_SIGNATURE", taken | {id_name})
        lines = [
            *field_map(planner, msg),
            f"{id_name}: _ClassVar[int | None] = {py_literal(info.data_type_id)}",
            f"{sig_name}: _ClassVar[int] = 0x{info.signature:016X}",
        ]
        if info.union:
            union_members(msg, ctx, view, emitter.module_code, lines)
        head, head_values = emitter.method_head(), emitter.method_from_head()
        methods = [
            emitter.method_encode(),
            emitter.method_decode(),
            *([head] if head is not None else []),
            *([head_values] if head_values is not None else []),
            emitter.method_put(),
            emitter.method_get(),
        ]
        body = "\n".join(lines) + "\n\n" + "\n\n".join(methods)
        class_body = "\n".join("    " + line if line else "" for line in body.split("\n"))
        return Contribution(
            class_body=class_body,
            module_code=("\n".join(emitter.module_code),) if emitter.module_code else (),
            imports=(f"from {ctx.root()} import _dronecan as _dc",),
        )

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        if not any(m.format is SourceFormat.DRONECAN for m in schema.messages):
            return {}
        return copied("_dronecan.py")


def union_members(msg: Message, ctx: ModuleContext, view: ClassView, module_code: list[str], lines: list[str]) -> None:
    """The branch table (into ``module_code``), ``union_field`` and the hooks that keep one branch held
    (``_dc.Union``), as class body ``lines``; Cyphal unions share them."""
    branches = []
    zeros = ["@staticmethod", "def _dc_zero(name: str) -> _Any:"]
    zeros.append('    """A fresh default value of branch ``name``."""')
    for f, fv in zip([f for f in msg.fields if not f.is_padding], view.fields, strict=True):
        branches.append(f"({py_literal(f.name)}, {py_literal(fv.ident)})")
        zero = FieldBuilder(ctx, f, optional=False).zero(f.type)
        zeros += [f"    if name == {py_literal(f.name)}:", f"        return {zero}"]
    zeros.append(f"    raise KeyError(name + {py_literal(' is not a field of ' + view.name)})")
    table = ctx.constant(view.name, "UNION")
    module_code.append(
        f"# the branches of {view.name}: (DSDL name, attribute)\n"
        f"{table} = _dc.Union({py_literal(view.name)}, ({', '.join(branches)},))"
    )
    meta = (
        '_m.meta(name="union_field", type="union tag", doc="DSDL name of the field this union holds (the one encoded)")'
    )
    lines += [
        f"union_field: str = _dataclasses.field(init=False, metadata={meta})",
        "",
        "def __post_init__(self) -> None:",
        '    """Select the one branch given (or the first, at its default); two given raise TypeError."""',
        f"    {table}.settle(self)",
        "",
        "def __setattr__(self, name: str, value: _Any) -> None:",
        '    """A value assigned to a branch selects it; assigning a branch name to union_field switches to it."""',
        f"    {table}.assign(self, name, value)",
        "",
        *zeros,
    ]


EXTENSION = _Codec()
