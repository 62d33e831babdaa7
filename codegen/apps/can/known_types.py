"""The DroneCAN types ``battgen can`` names and CRC-checks beyond those of the generated package.

A bus carries far more than batteries (NodeStatus, GetNodeInfo, parameters, ``uavcan.protocol.file.Read``);
their multi-frame transfers are CRC-checked only with their data type signature, which the DSDL defines. The
standard tree is the one the ``dronecan`` package ships (``dsdl_specs``: uavcan, ardupilot, dronecan, cuav,
com, mppt), read with battgen's own DSDL frontend, or a user's copy of dronecan/DSDL (``--dsdl DIR``). These
types are named and checked, not decoded: decoding is the generated package's job.

Cyphal's standard types are read from a user's DSDL tree (``--schemas DIR``, :func:`cyphal_types`): classes are
generated from it, so the transfers on their fixed subject ids are named and decoded too.
"""

from __future__ import annotations

import functools
import importlib.util
from pathlib import Path

from ...errors import BattgenError
from ...frontends import dsdl
from ...inputs.model import CyphalClass
from ...ir import DronecanKind

# (message | request | response, data type id) -> (DSDL full name, data type signature)
TypeTable = dict[tuple[str, int], tuple[str, int]]


def shipped_tree() -> Path | None:
    """The DSDL root the ``dronecan`` package ships, where it is installed (found without importing it)."""
    spec = importlib.util.find_spec("dronecan")
    if spec is None or spec.origin is None:
        return None
    root = Path(spec.origin).parent / "dsdl_specs"
    return root if root.is_dir() else None


@functools.cache
def standard_types(root: Path | None) -> TypeTable:
    """Every type with a data type id under the DSDL root ``root`` (None: no table)."""
    if root is None:
        return {}
    table: TypeTable = {}
    for message in dsdl.parse_dir(root).messages:
        info = message.dronecan
        if info is None or info.data_type_id is None:
            continue
        kind = "message" if info.kind is DronecanKind.MESSAGE else info.kind.value
        table.setdefault((kind, info.data_type_id), (info.full_name, info.signature))
    return table


def cyphal_types(root: Path) -> dict[str, CyphalClass]:
    """The Cyphal types of a user's DSDL tree (a copy of public_regulated_data_types, or a schema folder holding
    one), by DSDL full name, as classes generated from it once per process: those with a fixed port id
    (``uavcan.node.Heartbeat.1.0`` on 7509, ``uavcan.node.port.List``, ...) are then named and decoded on a bus
    without ``--cyphal-subject``. A BattgenError for a folder that holds no readable schemas."""
    from ...inputs.can.cyphal_ports import cyphal_classes
    from ..schemas.package import load_schemas, model_package

    if not root.is_dir():
        raise BattgenError(f"--schemas {root}: expected a folder of DSDL definitions, found no such folder")
    package = model_package(load_schemas(root), root)
    return cyphal_classes(package.__name__)
