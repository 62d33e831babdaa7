"""The Cyphal options of the commands that read CAN captures (``battgen can``, ``validate``, ``convert``, ``export``).

The subject tables are imported where a pair is given: ``battgen validate`` of a JSON file starts without them."""

from __future__ import annotations

import argparse

from ..inputs.model import MessageClass, package_name


def add_cyphal_subject(p: argparse.ArgumentParser) -> None:
    """``--cyphal-subject ID=TYPE``, as every command reading CAN captures takes it."""
    p.add_argument(
        "--cyphal-subject",
        action="append",
        default=[],
        metavar="ID=TYPE",
        help="the Cyphal type a subject id carries, as the node's uavcan.pub.<port>.id register says: a DSDL name "
        "(reg.udral.service.battery.Status.0.2, version optional) or a UDRAL battery port (energy_source, status, "
        "parameters); repeatable",
    )


def check_subjects(pairs: list[str], cls: MessageClass) -> None:
    """A wrong ``ID=TYPE`` pair said once (BattgenError), before any file is read."""
    if pairs:
        from ..inputs.can.cyphal_ports import cyphal_classes, subject_table

        subject_table(pairs, cyphal_classes(package_name(cls)))


def check_bundled_subjects(pairs: list[str]) -> None:
    """As :func:`check_subjects`, for a command that reads with the bundled package (``battgen export``)."""
    if pairs:
        from ..apps.schemas.package import bundled_package
        from ..inputs.can.cyphal_ports import cyphal_classes, subject_table

        subject_table(pairs, cyphal_classes(bundled_package().__name__))


def subject_message(pairs: list[str], package: str) -> str | None:
    """The message ``battgen validate`` checks by default given ``--cyphal-subject`` pairs: the first pair's type."""
    if not pairs:
        return None
    from ..inputs.can.cyphal_ports import cyphal_classes, find_type

    return find_type(pairs[0].partition("=")[2].strip(), cyphal_classes(package)).QUALIFIED_NAME
