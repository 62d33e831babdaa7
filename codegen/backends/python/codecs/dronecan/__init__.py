"""DroneCAN (UAVCAN v0) codec: bit-exact ``encode``/``decode`` generated per data type.

Every DroneCAN class gets ``encode(*, tao=True) -> bytes``, ``decode(data, *, tao=True)``,
``DATA_TYPE_ID`` / ``DATA_TYPE_SIGNATURE`` class attributes and, for a ``@union``, a
``union_field`` attribute naming the active field. The shared runtime (``_dronecan.py``) holds
float16 rounding, the bit-stream finisher, ``DecodeError`` and ``transfer_crc``.
Layout planning lives in :mod:`.plan`, code emission in :mod:`.emit`.
"""

from __future__ import annotations

from .....ir import CompositeType, Message, Schema, SourceFormat
from ...extensions import Contribution
from ...literals import py_literal
from ...module_context import ModuleContext
from ...runtime import copied
from ...views import ClassView
from .emit import MessageEmitter
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
            f"{id_name}: _ClassVar[int | None] = {py_literal(info.data_type_id)}",
            f"{sig_name}: _ClassVar[int] = 0x{info.signature:016X}",
        ]
        if info.union:
            emitter.union_attr = _free_name("union_field", taken | {id_name, sig_name})
            first = emitter.idents[0]
            meta = (
                f'_m.meta(name={py_literal(emitter.union_attr)}, type="union tag", '
                'doc="Name of the field this union holds (the one encoded)")'
            )
            default = py_literal(first)
            lines.append(f"{emitter.union_attr}: str = _dataclasses.field(default={default}, metadata={meta})")
        methods = [
            emitter.method_encode(),
            emitter.method_decode(),
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


EXTENSION = _Codec()
