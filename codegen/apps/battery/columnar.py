"""The concept mappings applied to whole columns: the IR's forward rules (``schemas/mappings/``)
interpreted over numpy arrays, one op at a time.

This is the fast path of ``battgen export``. It reads the same rules the Python backend turns
into the per-record converters (``generated/convert/_map_*.py``), with the same semantics: the
field's sentinel and the rule's ``unknown`` values mean unknown, factors come from the units in
the IR, a later rule that knows a value overrides an earlier one. Only the ops that map a record
format to the concepts are columnar; the PX4 code-path ops and the devicetree ones are not (no
record format is read through them) and raise :class:`NotColumnar`.
tests/apps/test_export_columnar.py checks it against the generated converters.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ...errors import BattgenError
from ...ir import CONCEPTS_ENDPOINT, Field, FieldRef, Rule, Unit, units
from ...ir import ops as o
from ...ir.mapping_values import ConstantRef, Number, Value
from ...ir.mapping_visitor import OpVisitor, visit
from .catalog import Catalog, SourceMapping
from .columns import ConceptColumn, LazyColumns, NDArray, length_key


class NotColumnar(BattgenError):
    """A rule whose op has no columnar form."""


def convert_columns(
    catalog: Catalog, source: SourceMapping, columns: Mapping[str, NDArray], n: int
) -> dict[str, ConceptColumn]:
    """The concept columns of ``n`` records of ``source.message``, given as ``columns`` (by the
    schema's field names; arrays as ``(n, capacity)`` matrices)."""
    converter = ColumnConverter(catalog, source, columns, n)
    for rule in source.rules:
        visit(rule, converter)
    return converter.out.done()


def _factor(frm: Unit | None, to: Unit | None) -> tuple[float, float]:
    if frm is None or to is None:
        return 1.0, 0.0
    return frm.factor_to(to)


def _affine(x: NDArray, mul: float, add: float) -> NDArray:
    """``float(x) * mul + add`` as the generated code computes it (each step only when it does)."""
    out = np.asarray(x, dtype=np.float64)
    if mul != 1.0:
        out = out * mul
    if add != 0.0:
        out = out + add
    return out


def _is_nan(value: object) -> bool:
    return isinstance(value, float) and math.isnan(value)


def _not_marker(x: NDArray, mark: float | int) -> NDArray:
    if _is_nan(mark):  # x == x is "not NaN" in one pass (and True for integers)
        return np.asarray(x == x)
    return np.asarray(x != mark)


def _and(a: NDArray | None, b: NDArray) -> NDArray:
    """``a & b`` where ``a`` None means everywhere."""
    return b if a is None else a & b


def leading_lengths(matrix: NDArray, mark: float | int | None) -> NDArray:
    """Per row, how many elements come before the first ``mark`` (all when there is none)."""
    width = matrix.shape[1]
    if mark is None or width == 0:
        return np.full(matrix.shape[0], width, np.int64)
    hit = ~_not_marker(matrix, mark)
    first = hit.argmax(axis=1)  # the first hit, or 0 where there is none
    return np.where(hit[np.arange(len(first)), first], first, width).astype(np.int64)


class ColumnConverter(OpVisitor[None]):
    """One mapping's forward rules over columns; ``out`` holds the concepts."""

    def __init__(self, catalog: Catalog, source: SourceMapping, columns: Mapping[str, NDArray], n: int) -> None:
        self.catalog = catalog
        self.source = source
        self.columns = columns
        self.n = n
        self.out = LazyColumns(catalog.concepts, n)

    # -- facts ---------------------------------------------------------------------------------

    def fld(self, ref: FieldRef) -> Field:
        # a number inside a composite (Cyphal's uavcan.si Scalars), its column by the path; or a field of another
        # message read beside this one (a rule reading two companions together)
        if "." in ref.field or ref.message != self.source.message.qualified_name:
            return self.catalog.schema.field_at(ref.message, ref.field)
        return self.source.message.field(ref.field)

    def col(self, ref: FieldRef) -> NDArray:
        return self.columns[ref.field]

    def pair(self, rule: Rule) -> tuple[FieldRef, ConceptColumn]:
        fmt, con = rule.sources[0], rule.targets[0]
        if fmt.message == CONCEPTS_ENDPOINT:
            fmt, con = con, fmt
        return fmt, self.out[con.field]

    def markers(self, f: Field, unknown: tuple[Number, ...]) -> list[float | int]:
        out: list[float | int] = []
        for m in ([f.invalid.value] if f.invalid is not None else []) + list(unknown):
            if not any((_is_nan(m) and _is_nan(s)) or m == s for s in out):
                out.append(m)
        return out

    def known(self, x: NDArray, marks: list[float | int]) -> NDArray | None:
        """Where ``x`` is none of ``marks`` (None: everywhere)."""
        ok: NDArray | None = None
        for m in marks:
            ok = _and(ok, _not_marker(x, m))
        return ok

    def constant(self, value: Value | None, refs: tuple[FieldRef, ...]) -> object:
        if not isinstance(value, ConstantRef):
            return value
        msg = self.source.message
        schema = self.catalog.schema
        owners = [schema.owner_at(r.message, r.field) for r in refs if r.message == msg.qualified_name]
        for c in (*msg.constants, *(c for owner in owners for c in owner.constants)):
            if c.name == value.name:
                return c.value
        for e in self.catalog.schema.enums:
            for entry in e.entries:
                if entry.name == value.name:
                    return entry.value
        raise BattgenError(f"{msg.qualified_name}: no constant {value.name!r}")

    def mask(self, name: ConstantRef) -> int:
        """A constant as a bit mask: bit masks as they are, bit indices (uORB FAULT_*) as 1 << i."""
        value = self.constant(name, ())
        for e in self.source.message.enums:
            if any(x.name == name.name for x in e.entries) and e.kind.value == "bit_index":
                return 1 << int(str(value))
        return int(str(value))

    # -- numbers -------------------------------------------------------------------------------

    def visit_scale(self, rule: Rule, op: o.Scale) -> None:
        fmt, con = self.pair(rule)
        f = self.fld(fmt)
        x = self.col(fmt)
        if x.ndim != 1:
            raise NotColumnar(f"{rule.location}: scale of the list field {f.name} (devicetree) is not columnar")
        ok = self.known(x, self.markers(f, op.unknown))
        if op.valid_above is not None:
            ok = _and(ok, x > op.valid_above)
        if op.valid_max is not None:
            ok = _and(ok, x <= op.valid_max)
        named = units.lookup(op.unit) if op.unit is not None else None
        mul, add = _factor(f.unit or named or con.concept.unit, con.concept.unit)
        value = _affine(x, -mul, -add) if op.negate else _affine(x, mul, add)
        if op.negate and add == 0.0:  # the field counts the other way; + 0.0 keeps a zero from reading -0.0
            value = value + 0.0
        con.set(value, ok, take=value is not x)

    def visit_copy(self, rule: Rule, op: o.Copy) -> None:
        fmt, con = self.pair(rule)
        f = self.fld(fmt)
        x = self.col(fmt)
        kind = con.concept.kind
        if kind == "text":
            texts = np.array([_text_in(v) for v in x], dtype=object)
            con.set(texts, np.array([t is not None for t in texts], dtype=bool))
            return
        ok = self.known(x, self.markers(f, op.unknown))
        if kind == "bool":
            value: NDArray = x.astype(bool)
        elif op.add:
            value = x.astype(np.int64) + int(op.add) if isinstance(op.add, int) else x + op.add
        else:
            value = x
        con.set(value, ok)

    def visit_const(self, rule: Rule, op: o.Const) -> None:
        value = self.constant(op.value, rule.targets)
        for ref in rule.targets:
            con = self.out[ref.field]
            if con.concept.kind == "choice":
                con.set(con.concept.choices.index(str(value)))
            else:
                con.set(value)

    def visit_soc_hybrid(self, rule: Rule, op: o.SocHybrid) -> None:
        remaining, full = rule.sources[:2]
        con = self.out[rule.targets[0].field]
        e = self.col(remaining).astype(np.float64)
        full_v = self.col(full).astype(np.float64)
        by_energy = (e == e) & (full_v == full_v) & (e > 0) & (full_v > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.minimum(e / np.where(by_energy, full_v, 1.0), 1.0)
        if len(rule.sources) == 3:
            percent = rule.sources[2]
            f = self.fld(percent)
            p = self.col(percent)
            ok = self.known(p, self.markers(f, op.unknown))
            if op.valid_max is not None:
                ok = _and(ok, p <= op.valid_max)
            con.set(_affine(p, *_factor(f.unit, con.concept.unit)), _and(ok, ~by_energy))
        con.set(ratio, by_energy)

    # -- bits and choices ----------------------------------------------------------------------

    def visit_flag(self, rule: Rule, op: o.Flag) -> None:
        fmt, con = self.pair(rule)
        con.set((self.col(fmt).astype(np.int64) & self.mask(op.mask)) != 0)

    def visit_flag_choice(self, rule: Rule, op: o.FlagChoice) -> None:
        fmt, con = self.pair(rule)
        hit = (self.col(fmt).astype(np.int64) & self.mask(op.mask)) != 0
        con.set(con.concept.choices.index(op.value), hit)

    def visit_flags(self, rule: Rule, op: o.Flags) -> None:
        fmt, con = self.pair(rule)
        x = self.col(fmt).astype(np.int64)
        table = {bit.choice: self.mask(bit.mask) for bit in op.map}
        rows = np.flatnonzero(x)  # records with any bit set: few (a fault is rare)
        some = np.zeros(len(rows), np.int64)
        for i, choice in enumerate(con.concept.choices):
            if choice in table and len(rows):
                some |= ((x[rows] & table[choice]) != 0).astype(np.int64) << i
        bits = np.zeros(self.n, np.int64)
        bits[rows] = some
        con.set(bits)

    def visit_choice(self, rule: Rule, op: o.Choice) -> None:
        fmt, con = self.pair(rule)
        x = self.col(fmt).astype(np.int64)
        codes = np.full(self.n, -1, np.int16)
        for entry in op.map:
            value = self.constant(entry.value, (fmt,))
            codes[x == int(str(value))] = con.concept.choices.index(entry.choice)
        # the generated code assigns the lookup whatever it finds: no match is unknown again
        con.assign(np.maximum(codes, 0), codes >= 0)

    def visit_value_flags(self, rule: Rule, op: o.ValueFlags) -> None:
        fmt, con = self.pair(rule)
        x = self.col(fmt).astype(np.int64)
        bits = np.zeros(self.n, np.int64)
        for entry in op.map:
            value = self.constant(entry.value, (fmt,))
            bits[x == int(str(value))] = 1 << con.concept.choices.index(entry.choice)
        con.set(bits)

    # -- cells ---------------------------------------------------------------------------------

    def visit_cells(self, rule: Rule, op: o.Cells) -> None:
        fmt, con = self.pair(rule)
        f = self.fld(fmt)
        m = self.col(fmt)
        mark = f.invalid.value if f.invalid is not None and f.invalid.per_element else None
        given = self.columns.get(length_key(fmt.field))  # a variable-length array's own lengths
        room = m.shape[1] if given is None else given
        count = self.columns[op.count_field].astype(np.int64) if op.count_field is not None else None
        if count is not None and count.all():  # every record gives its count (the usual): it alone decides
            lengths = np.minimum(count, room)
        else:
            lengths = leading_lengths(m, mark)
            if given is not None:
                lengths = np.minimum(lengths, given)
            if count is not None:
                lengths = np.where(count != 0, np.minimum(count, room), lengths)
        if f.invalid is not None and f.invalid.first_decides and m.shape[1]:  # MAVLink [X:]: element 0 speaks
            lengths = np.where(_not_marker(m[:, 0], f.invalid.value), lengths, 0)
        # elements past every row's length are dropped anyway: a pack of 4 cells in PX4's 14 slots
        # converts 4 columns, not 14
        m = m[:, : int(lengths.max()) if len(lengths) else 0]
        mul, add = _factor(f.unit or con.concept.unit, con.concept.unit)
        values = _affine(m, mul, add)
        if values is m:  # a float64 field as it is: the NaNs below must not write into the log's columns
            values = values.copy()
        if len(lengths) and bool((lengths == lengths[0]).all()):  # every pack as long (the usual)
            values[:, int(lengths[0]) :] = np.nan
        else:
            np.copyto(values, np.nan, where=np.arange(m.shape[1]) >= lengths[:, None])
        if mark is not None and not _is_nan(mark):  # a NaN marker is NaN in the values already
            np.copyto(values, np.nan, where=~_not_marker(m, mark))
        con.set_list(values, lengths, lengths > 0)

    def visit_mavlink_voltages(self, rule: Rule, op: o.MavlinkVoltages) -> None:
        main_ref, ext_ref = rule.sources
        pack, cells = (self.out[t.field] for t in rule.targets)
        main_f, ext_f = self.fld(main_ref), self.fld(ext_ref)
        main_mark = int(main_f.invalid.value) if main_f.invalid is not None else 0xFFFF
        ext_mark = int(ext_f.invalid.value) if ext_f.invalid is not None else 0
        main, ext = self.col(main_ref).astype(np.int64), self.col(ext_ref).astype(np.int64)
        n_main = leading_lengths(main, main_mark)
        n_ext = np.where(n_main == main.shape[1], leading_lengths(ext, ext_mark), 0)
        both = np.concatenate([main, ext], axis=1)
        lengths = n_main + n_ext
        used = np.concatenate(
            [np.arange(main.shape[1]) < n_main[:, None], np.arange(ext.shape[1]) < n_ext[:, None]], axis=1
        )
        total = np.where(used, both, 0).sum(axis=1)
        mul, add = _factor(main_f.unit, pack.concept.unit)
        pack.set(_affine(total, mul, add), lengths > 0)
        is_cells = (lengths > 1) & (both[:, 0] != main_mark - 1)
        values = np.where(used, _affine(both, mul, add), np.nan)
        cells.set_list(values, lengths, is_cells)

    # -- ops no record format maps to the concepts through ---------------------------------------

    def _not_columnar(self, rule: Rule) -> None:
        raise NotColumnar(f"{rule.location}: the {rule.op.NAME} op has no columnar form")

    def visit_dt_pack(self, rule: Rule, op: o.DtPack) -> None:
        self._not_columnar(rule)

    def visit_ocv_soc(self, rule: Rule, op: o.OcvSoc) -> None:
        self._not_columnar(rule)

    def visit_same_names(self, rule: Rule, op: o.SameNames) -> None:
        self._not_columnar(rule)

    def visit_zero_all(self, rule: Rule, op: o.ZeroAll) -> None:
        self._not_columnar(rule)

    def visit_px4_convert(self, rule: Rule, op: o.PX4Convert) -> None:
        self._not_columnar(rule)

    def visit_px4_int(self, rule: Rule, op: o.PX4Int) -> None:
        self._not_columnar(rule)

    def visit_px4_warning(self, rule: Rule, op: o.PX4Warning) -> None:
        self._not_columnar(rule)

    def visit_enum_map(self, rule: Rule, op: o.EnumMap) -> None:
        self._not_columnar(rule)

    def visit_bits_from(self, rule: Rule, op: o.BitsFrom) -> None:
        self._not_columnar(rule)

    def visit_px4_stream_cells(self, rule: Rule, op: o.PX4StreamCells) -> None:
        self._not_columnar(rule)

    def visit_px4_receiver_cells(self, rule: Rule, op: o.PX4ReceiverCells) -> None:
        self._not_columnar(rule)

    def visit_px4_bridge_cells(self, rule: Rule, op: o.PX4BridgeCells) -> None:
        self._not_columnar(rule)

    def visit_px4_cell_list(self, rule: Rule, op: o.PX4CellList) -> None:
        self._not_columnar(rule)

    def visit_px4_aux_capacity(self, rule: Rule, op: o.PX4AuxCapacity) -> None:
        self._not_columnar(rule)

    def visit_px4_bridge_estimates(self, rule: Rule, op: o.PX4BridgeEstimates) -> None:
        self._not_columnar(rule)

    def visit_px4_udral_energy(self, rule: Rule, op: o.PX4UdralEnergy) -> None:
        self._not_columnar(rule)

    def visit_ardupilot_temperature(self, rule: Rule, op: o.ArduPilotTemperature) -> None:
        self._not_columnar(rule)

    def visit_ardupilot_current(self, rule: Rule, op: o.ArduPilotCurrent) -> None:
        self._not_columnar(rule)

    def visit_ardupilot_cells(self, rule: Rule, op: o.ArduPilotCells) -> None:
        self._not_columnar(rule)

    def visit_ardupilot_estimates(self, rule: Rule, op: o.ArduPilotEstimates) -> None:
        self._not_columnar(rule)


def _text_in(value: object) -> str | None:
    """A text field's content (bytes are UTF-8, NUL padding dropped); empty means unknown."""
    if isinstance(value, bytes | bytearray):
        value = bytes(value).split(b"\x00", 1)[0].decode("utf-8", "replace")
    return str(value) if value else None
