"""PX4's cell-voltage code paths as Rust (the MAVLink stream and receiver, the uavcannode
publisher; the C backend's ``convert_px4_cells``, in Rust), as the Python backend's
``px4_cells.py`` and the run-time ``_cells.py`` compute them: f32 at each step, C's float to
integer conversions."""

from __future__ import annotations

from ...ir import ArrayType, Field, Rule
from ...ir import ops as o
from .convert_context import RustBase, cast, paren
from .convert_values import Unsupported, f32, f32_literal, literal
from .types import capacity


def _array(f: Field) -> ArrayType:
    if not isinstance(f.type, ArrayType):
        raise Unsupported(f"{f.name}: not an array")
    return f.type


def _factor(f: Field, to: Field) -> float:
    return f.unit.factor_to(to.unit)[0] if f.unit is not None and to.unit is not None else 1.0


class PX4CellOps(RustBase):
    def visit_px4_cell_list(self, rule: Rule, op: o.PX4CellList) -> None:
        """uavcannode: ``voltage_cell = voltage_cell_v[0 .. cell_count)``, more than fit reported clamped."""
        cells, count = rule.sources
        dst = rule.targets[0]
        cap = _array(self.fld(cells)).capacity or 0
        target = self.t(dst)
        if not _array(self.fld(dst)).dynamic:
            raise Unsupported("a cell list into a fixed array")
        dcap = capacity(_array(self.fld(dst)))
        self.emit(
            f"let mut n = {cast(self.s(count), self.rust(count), 'usize')};",
            f"if n > {cap} {{ r.add(LossKind::Clamped, {self.label(dst)}); n = {cap}; }}",
            f"let n = n.min({dcap});",
            f"{target}_len = n;",
            f"for i in 0..n {{ {target}[i] = {self.store_c(dst, f'{self.s(cells)}[i]')}; }}",
        )

    def visit_px4_receiver_cells(self, rule: Rule, op: o.PX4ReceiverCells) -> None:
        """The receiver: cells while below the marker, v / div in f32, summed in f32."""
        (volts,) = rule.sources
        cells, count, total = rule.targets
        vf, cf = self.fld(volts), self.fld(cells)
        n_cells = _array(cf).capacity or 0
        limit = min(_array(vf).capacity or 0, n_cells)
        mark = int(vf.invalid.value) if vf.invalid is not None else 0xFFFF
        div = f32(1.0 / _factor(vf, cf))
        src, dst = self.s(volts), self.t(cells)
        self.emit(
            "let mut n = 0;",
            "let mut acc = 0.0_f32;",
            f"while n < {limit} && {src}[n] < {mark} {{ n += 1; }}",
            f"{dst} = [0.0; {n_cells}];",
            "for i in 0..n {",
            f"{dst}[i] = (f64::from({src}[i]) / f64::from({f32_literal(div)})) as f32;",
            f"acc += {dst}[i];",
            "}",
            f"{self.t(count)} = {cast('n', 'usize', self.rust(count))};",
            f"{self.t(total)} = acc;",
        )

    def visit_px4_stream_cells(self, rule: Rule, op: o.PX4StreamCells) -> None:
        """The stream: UINT16_MAX / 0 fills; the pack voltage in chunks when no cell is known, else the cells."""
        volt, cells, count, connected = rule.sources
        main, ext = rule.targets
        mf, ef = self.fld(main), self.fld(ext)
        mul = f32_literal(f32(_factor(self.fld(cells), mf)))
        fill = int(mf.invalid.value) if mf.invalid is not None else 0xFFFF
        threshold = f32_literal(f32(float(op.cell_threshold if op.cell_threshold is not None else 0.0001)))
        n_main, n_ext = _array(mf).capacity or 0, _array(ef).capacity or 0
        n_cells = _array(self.fld(cells)).capacity or 0
        m, e, c = self.t(main), self.t(ext), self.s(cells)
        chunk = fill - 1
        slots = min(n_cells, n_main + n_ext)
        conn = self.s(connected)
        conn_test = conn if self.rust(connected) == "bool" else f"{conn} != 0"
        self.emit(
            f"{m} = [{literal(self.prim(main), fill)}; {n_main}];",
            f"{e} = [{literal(self.prim(ext), 0)}; {n_ext}];",
            f"if {conn_test} {{",
            f"if {self.s(count)} == 0 || {c}[0] < {threshold} {{",
            f"let total: f32 = {self.s(volt)} * {mul};",
            f"let fields = i64::from((total as i32) / {chunk}) + 1;",  # C division truncates
            f"if (1..={n_main}).contains(&fields) {{",
            "let mut rest = total;",
            "let last = (fields - 1) as usize;",
            f"for slot in {m}.iter_mut().take(last) {{",
            f"*slot = {chunk};",
            f"rest -= {float(chunk)}_f32;",
            "}",
            f"{m}[last] = {self.store_c(main, 'rest')};",
            "} else {",
            f"r.add(LossKind::Clamped, {self.label(main)});",
            "}",
            "} else {",
            f"let slots = {paren(cast(self.s(count), self.rust(count), 'usize'))}.min({slots});",
            "for i in 0..slots {",
            f"let v = {self.store_c(main, f'{c}[i] * {mul}')};",
            f"if i < {n_main} {{ {m}[i] = v; }} else {{ {e}[i - {n_main}] = v; }}",
            "}",
            "}",
            "}",
        )
