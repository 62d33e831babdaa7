"""Parameter files as users have them, told apart by their content (never the extension alone).

- ArduPilot layout: one ``NAME,VALUE`` (Mission Planner ``.param``, ArduPilot's own
  ``Tools/Frame_params/*.param`` and comma-separated ``.params``) or ``NAME VALUE`` (MAVProxy
  ``.parm``, spaces or tabs) a line; ``#`` starts a comment (also after a value).
- QGroundControl layout: ``#`` comment lines, then tab-separated ``vehicle-id component-id NAME VALUE
  TYPE`` with TYPE a MAV_PARAM_TYPE (9 = REAL32, 2 = INT8, ...).

The layout is the QGC one when the first data line starts with two decimal ids, else ArduPilot's.
CRLF line ends and a UTF-8 byte-order mark are fine. A parameter written twice keeps its last
value, as loading the file into a vehicle would (:func:`repeats` lists them, for a warning). Values
are read as int when written as an integer (or 0x hex, as pymavlink's mavparm reads them), else
float; NaN and infinities are refused. Every error names file and line and says what was expected.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ...errors import BattgenError, LocatedError
from ...text.brief import brief
from ...text.escape import shown
from ...text.files import read_whole

Value = int | float

NAME = re.compile(r"[A-Za-z0-9_]{1,16}")  # MAVLink param_id: at most 16 characters
_INT = re.compile(r"[+-]?[0-9]+")
_HEX = re.compile(r"0[xX][0-9A-Fa-f]+")
# MAV_PARAM_TYPE values a QGC file may carry, and which of them hold integers
MAV_PARAM_TYPES: dict[int, str] = {
    1: "UINT8", 2: "INT8", 3: "UINT16", 4: "INT16", 5: "UINT32",
    6: "INT32", 7: "UINT64", 8: "INT64", 9: "REAL32", 10: "REAL64",
}  # fmt: skip
_FLOAT_TYPES = frozenset({9, 10})
# our parameter types (codegen.frontends.pdef) as MAV_PARAM_TYPE
TYPE_OF: dict[str, int] = {"int8": 2, "int16": 4, "int32": 6, "float32": 9}

QGC_SUFFIXES = (".params",)
ARDUPILOT_SUFFIXES = (".param", ".parm")


class ParameterFileError(LocatedError):
    """A malformed parameter file: names the file, the 1-based line and what was expected."""


@dataclass(frozen=True)
class ParamEntry:
    name: str
    value: Value
    line: int
    mav_type: int | None = None  # QGC files state it
    vehicle: int | None = None
    component: int | None = None


def is_parameter_file(path: Path) -> bool:
    return path.suffix.lower() in QGC_SUFFIXES + ARDUPILOT_SUFFIXES


_QGC_START = re.compile(r"\s*[0-9]+\s+[0-9]+\s")


def is_qgc_text(lines: Sequence[str]) -> bool:
    """The QGroundControl layout: the first data line starts with vehicle and component ids."""
    for line in lines:
        body = line.strip()
        if body and not body.startswith("#"):
            return bool(_QGC_START.match(line))
    return False


def parse_text(text: str, display: str, *, qgc: bool | None = None) -> list[ParamEntry]:
    """Entries in file order, a repeated parameter at each of its lines (the last one counts).
    ``qgc`` None: the layout from the content (:func:`is_qgc_text`)."""
    # lines as editors and file:line number them: \n, \r\n and \r break a line; str.splitlines would also
    # break at \x85, \x0c, \u2028..., so a reported line number would not be the file's
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    if qgc is None:
        qgc = is_qgc_text(lines)
    entries: list[ParamEntry] = []
    for number, raw in enumerate(lines, start=1):
        entry = _qgc_line(raw, display, number) if qgc else _ardupilot_line(raw, display, number)
        if entry is not None:
            entries.append(entry)
    return entries


@dataclass(frozen=True)
class Repeat:
    """A parameter written more than once in one set: the value at its last line is loaded."""

    name: str
    lines: tuple[int, ...]
    values: tuple[Value, ...]
    vehicle: int | None = None
    component: int | None = None

    def message(self) -> str:
        at = ", ".join(str(n) for n in self.lines)
        return (
            f"{self.name} is set {len(self.lines)} times (lines {at}): the last value, "
            f"{format_value(self.values[-1])}, is the one a vehicle loads"
        )


def repeats(entries: Iterable[ParamEntry]) -> list[Repeat]:
    """The parameters written more than once in a set, in order of their first line."""
    seen: dict[tuple[int | None, int | None, str], list[ParamEntry]] = {}
    for e in entries:
        seen.setdefault((e.vehicle, e.component, e.name), []).append(e)
    return [
        Repeat(name, tuple(e.line for e in group), tuple(e.value for e in group), vehicle, component)
        for (vehicle, component, name), group in seen.items()
        if len(group) > 1
    ]


def load(path: Path, display: str | None = None) -> list[ParamEntry]:
    """Read a parameter file of either layout (told from the content)."""
    shown = display or path.as_posix()
    data = read_whole(path, shown, ParameterFileError, "a parameter file")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParameterFileError(shown, data[: exc.start].count(b"\n") + 1, "expected UTF-8 text") from None
    return parse_text(text, shown)


def sets(entries: Iterable[ParamEntry]) -> dict[tuple[int | None, int | None], list[ParamEntry]]:
    """The entries by parameter set: a .param file is one set (key ``(None, None)``); a QGC
    .params file holds one per (vehicle, component) pair, in order of first appearance."""
    groups: dict[tuple[int | None, int | None], list[ParamEntry]] = {}
    for entry in entries:
        groups.setdefault((entry.vehicle, entry.component), []).append(entry)
    return groups


def value_sets(entries: Iterable[ParamEntry]) -> list[tuple[int, dict[str, Value]]]:
    """One item per parameter set (see :func:`sets`): ``(line of its first parameter, {NAME: value})``;
    a repeated parameter has its last value."""
    return [(group[0].line, {e.name: e.value for e in group}) for group in sets(entries).values()]


def read_parameter_file(path: Path) -> Iterator[tuple[int, dict[str, Value]]]:
    """One instance per parameter set of a file, as :func:`value_sets`. Feed a set to a generated
    model through :func:`select` (e.g. ``BattParams.from_dict(select(values, BattParams))``)."""
    yield from value_sets(load(path))


def select(values: Mapping[str, Value], model: type | Iterable[str]) -> dict[str, Value]:
    """The parameters a model (a generated class, or field names) knows, dropping the rest of a full dump."""
    if isinstance(model, type):
        names = {f.metadata.get("name", f.name) for f in dataclasses.fields(model)}
    else:
        names = set(model)
    return {k: v for k, v in values.items() if k in names}


def format_value(value: Value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, int):
        return str(value)
    return format(value, ".9g")


def write_param(items: Sequence[tuple[str, Value, str]], *, header: Sequence[str] = ()) -> str:
    """ArduPilot .param text: ``NAME,VALUE`` lines, each with its comment (``# ...``) when given. Header and
    comments quote inputs (a file name, a devicetree node): shown escaped, so none can end its line and
    start a parameter line of its own."""
    out = [f"# {shown(h)}" if h else "#" for h in header]
    for name, value, comment in items:
        _check_name(name)
        line = f"{name},{format_value(value)}"
        out.append(f"{line}  # {shown(comment)}" if comment else line)
    return "\n".join(out) + "\n"


def write_qgc(
    items: Sequence[tuple[str, Value, int]], *, vehicle: int = 1, component: int = 1, header: Sequence[str] = ()
) -> str:
    """QGroundControl .params text; each item is (NAME, value, MAV_PARAM_TYPE); the header escaped as
    :func:`write_param`'s."""
    out = [f"# {shown(h)}" if h else "#" for h in header]
    out.append("# Vehicle-Id Component-Id Name Value Type")
    for name, value, mav_type in items:
        _check_name(name)
        if mav_type not in MAV_PARAM_TYPES:
            raise BattgenError(f"{name}: expected a MAV_PARAM_TYPE 1..10, got {mav_type}")
        out.append(f"{vehicle}\t{component}\t{name}\t{format_value(value)}\t{mav_type}")
    return "\n".join(out) + "\n"


def _check_name(name: str) -> None:
    if not NAME.fullmatch(name):
        raise BattgenError(f"expected a parameter name of 1 to 16 letters, digits and _, got {brief(name)}")


# A MAVLink parameter is a float32 or an integer of at most 32 bits on the wire: a value of more digits
# than any of those holds is refused here, before int() (which refuses over 4,300 digits) or a message quotes it.
MAX_DIGITS = 40


def _value(text: str, display: str, line: int, *, integer: bool = False) -> Value:
    if len(text) > MAX_DIGITS and (_HEX.fullmatch(text) or _INT.fullmatch(text)):
        raise ParameterFileError(
            display,
            line,
            f"expected a parameter value (float32 or a 32-bit integer), got a number of {len(text)} digits",
        )
    if _HEX.fullmatch(text):
        return int(text, 16)
    if _INT.fullmatch(text):
        return int(text)
    try:
        number = float(text)
    except ValueError:
        raise ParameterFileError(display, line, f"expected a number as the value, got {brief(text)}") from None
    if not math.isfinite(number):
        raise ParameterFileError(display, line, f"expected a finite number as the value, got {brief(text)}")
    if integer:
        if not number.is_integer():
            raise ParameterFileError(
                display, line, f"expected an integer value for an integer MAV_PARAM_TYPE, got {brief(text)}"
            )
        return int(number)
    return number


def _name(text: str, display: str, line: int) -> str:
    if not NAME.fullmatch(text):
        raise ParameterFileError(
            display, line, f"expected a parameter name of 1 to 16 letters, digits and _, got {brief(text)}"
        )
    return text


def _ardupilot_line(raw: str, display: str, line: int) -> ParamEntry | None:
    body = raw.split("#", 1)[0].strip()
    if not body:
        return None
    parts = [p for p in re.split(r"[,\s]+", body) if p]
    if len(parts) != 2:
        raise ParameterFileError(display, line, f"expected 'NAME,VALUE' or 'NAME VALUE', got {brief(body)}")
    return ParamEntry(_name(parts[0], display, line), _value(parts[1], display, line), line)


def _qgc_line(raw: str, display: str, line: int) -> ParamEntry | None:
    body = raw.strip()
    if not body or body.startswith("#"):
        return None
    parts = body.split("\t") if "\t" in body else body.split()
    parts = [p.strip() for p in parts]
    if len(parts) != 5:
        raise ParameterFileError(
            display,
            line,
            f"expected 5 tab-separated columns (vehicle id, component id, name, value, type), got {len(parts)}",
        )
    ids = []
    for label, text in (("vehicle id", parts[0]), ("component id", parts[1]), ("type", parts[4])):
        if not re.fullmatch(r"[0-9]{1,3}", text):
            raise ParameterFileError(display, line, f"expected a decimal {label}, got {brief(text)}")
        ids.append(int(text))
    vehicle, component, mav_type = ids
    if mav_type not in MAV_PARAM_TYPES:
        raise ParameterFileError(display, line, f"expected a MAV_PARAM_TYPE from 1 to 10 as type, got {mav_type}")
    value = _value(parts[3], display, line, integer=mav_type not in _FLOAT_TYPES)
    if mav_type in _FLOAT_TYPES and isinstance(value, int):
        value = float(value)
    return ParamEntry(_name(parts[2], display, line), value, line, mav_type, vehicle, component)
