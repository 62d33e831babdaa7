"""Which Cyphal type each subject of a bus carries: Cyphal/CAN frames name a port, never a type.

A Cyphal node is configured with the subject id of each port it publishes (its ``uavcan.pub.<port>.id``
register); a reader of its transfers must be told the same. :func:`subject_table` builds the table from
``ID=TYPE`` pairs (``--cyphal-subject 4096=reg.udral.service.battery.Status.0.2``) and from the fixed port
ids the generated package's types declare. TYPE is a DSDL full name, its version optional (the newest the
package has), or one of the ports of UDRAL's battery service as its ``_.0.1`` lists them: ``energy_source``,
``status``, ``parameters`` (``battery_status``, ``battery_parameters`` as PX4 names them).
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
from collections.abc import Iterable, Mapping

from ...errors import BattgenError, did_you_mean
from ..model import CyphalClass
from .cyphal_wire import SUBJECT_MASK

Subjects = Mapping[int, CyphalClass]
_HALVES = (".Request", ".Response")
_DRONE = "reg.drone."
# the subjects of reg.udral.service.battery._.0.1 (its own table) and the type each carries; PX4's Cyphal
# battery subscriber names the last two battery_status and battery_parameters (its port registers)
BATTERY_PORTS = {
    "energy_source": "reg.udral.physics.electricity.SourceTs",
    "status": "reg.udral.service.battery.Status",
    "parameters": "reg.udral.service.battery.Parameters",
    "battery_status": "reg.udral.service.battery.Status",
    "battery_parameters": "reg.udral.service.battery.Parameters",
}


def dsdl_name(cls: CyphalClass) -> str:
    """The DSDL full name of a generated class: ``cyphal.reg.udral.service.battery.Status_0_2`` ->
    ``reg.udral.service.battery.Status.0.2`` (``__0_1``, the service marker ``_``, -> ``_.0.1``; a service's
    halves keep their ``.Request`` / ``.Response``)."""
    qualified, half = cls.QUALIFIED_NAME.removeprefix("cyphal."), ""
    if qualified.endswith(_HALVES):
        qualified, _, half = qualified.rpartition(".")
        half = "." + half
    namespace, _, short = qualified.rpartition(".")
    name, major, minor = short.rsplit("_", 2)
    return f"{namespace}.{name}.{major}.{minor}{half}"


@functools.cache
def cyphal_classes(package: str) -> dict[str, CyphalClass]:
    """Every Cyphal class of a generated package, by DSDL full name."""
    try:
        root = importlib.import_module(package + ".cyphal")
    except ImportError:
        return {}
    found: dict[str, CyphalClass] = {}
    for info in pkgutil.walk_packages(root.__path__, root.__name__ + "."):
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if isinstance(value, type) and value.__module__ == module.__name__ and isinstance(value, CyphalClass):
                found[dsdl_name(value)] = value
    return found


def _version(name: str) -> tuple[int, int]:
    major, minor = name.rsplit(".", 2)[1:]
    return int(major), int(minor)


def find_type(text: str, classes: Mapping[str, CyphalClass]) -> CyphalClass:
    """The class a TYPE names: a full name with its version, a name with its major version only, or none (the
    newest), or a UDRAL battery port."""
    wanted = BATTERY_PORTS.get(text, text)
    if wanted.startswith(_DRONE):  # the older namespace NXP's BMS publishes: read as its reg.udral twin
        wanted = "reg.udral." + wanted.removeprefix(_DRONE)
    if wanted in classes:
        return classes[wanted]
    versions = [n for n in classes if n.startswith(wanted + ".") and n[len(wanted) + 1 :].count(".") < 2]
    versions = [n for n in versions if n[len(wanted) + 1 :].replace(".", "").isdigit()]
    if versions:
        return classes[max(versions, key=_version)]
    raise BattgenError(
        f"--cyphal-subject: expected a Cyphal type the schemas define or a battery port "
        f"({', '.join(BATTERY_PORTS)}), found {text!r}; {did_you_mean(text, classes, what='Cyphal types')}"
    )


def subject_table(pairs: Iterable[str], classes: Mapping[str, CyphalClass]) -> dict[int, CyphalClass]:
    """Subject id -> class: the types' fixed port ids, then each ``ID=TYPE`` pair (which wins)."""
    table = {cls.FIXED_PORT_ID: cls for cls in classes.values() if cls.FIXED_PORT_ID is not None and _is_message(cls)}
    for pair in pairs:
        port, sep, name = pair.partition("=")
        if not sep or not port.strip().isdigit() or int(port) > SUBJECT_MASK or not name.strip():
            raise BattgenError(
                f"--cyphal-subject: expected ID=TYPE with a subject id 0..{SUBJECT_MASK}, "
                f"e.g. 4096=reg.udral.service.battery.Status.0.2, found {pair!r}"
            )
        table[int(port)] = find_type(name.strip(), classes)
    return table


def _is_message(cls: CyphalClass) -> bool:
    """A message type (the halves of a service, ``<Name>.Request``/``.Response``, travel on service ports)."""
    return not cls.QUALIFIED_NAME.endswith(_HALVES)
