"""PX4's cell-voltage code paths as C (the MAVLink stream and receiver, the uavcannode publisher), as
``codegen/backends/python/converters/px4_cells.py`` and the run-time ``_cells.py`` compute them: float32
at each step, C's float to integer conversions."""

from __future__ import annotations

from ...ir import ArrayType, Field, Rule
from ...ir import ops as o
from .convert_context import CBase
from .convert_values import Unsupported, f32, f32_literal
from .types import scalar


def _array(f: Field) -> ArrayType:
    if not isinstance(f.type, ArrayType):
        raise Unsupported(f"{f.name}: not an array")
    return f.type


def _factor(f: Field, to: Field) -> float:
    return f.unit.factor_to(to.unit)[0] if f.unit is not None and to.unit is not None else 1.0


class PX4CellOps(CBase):
    def visit_px4_cell_list(self, rule: Rule, op: o.PX4CellList) -> None:
        """uavcannode: ``voltage_cell = voltage_cell_v[0 .. cell_count)``, more than fit reported clamped."""
        cells, count = rule.sources
        dst = rule.targets[0]
        cap = _array(self.fld(cells)).capacity or 0
        target = self.t(dst)
        if not _array(self.fld(dst)).dynamic:
            raise Unsupported("a cell list into a fixed array")
        self.emit(
            "size_t i;",
            f"size_t n = (size_t){self.s(count)};",
            f"if (n > {cap}u) {{ battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {self.label(dst)}); n = {cap}u; }}",
            f"{target}_len = (uint16_t)n;",
            f"for (i = 0; i < n; i++) {{ {target}[i] = {self.store_c(dst, f'{self.s(cells)}[i]')}; }}",
        )

    def visit_px4_receiver_cells(self, rule: Rule, op: o.PX4ReceiverCells) -> None:
        """The receiver: cells while below the marker, v / div in float32, summed in float32."""
        (volts,) = rule.sources
        cells, count, total = rule.targets
        vf, cf = self.fld(volts), self.fld(cells)
        n_cells = _array(cf).capacity or 0
        limit = min(_array(vf).capacity or 0, n_cells)
        mark = int(vf.invalid.value) if vf.invalid is not None else 0xFFFF
        div = f32(1.0 / _factor(vf, cf))
        src, dst = self.s(volts), self.t(cells)
        self.emit(
            "size_t i, n = 0;",
            "float acc = 0.0f;",
            f"while (n < {limit}u && {src}[n] < {mark}u) {{ n++; }}",
            f"for (i = 0; i < {n_cells}u; i++) {{ {dst}[i] = 0.0f; }}",
            "for (i = 0; i < n; i++) {",
            f"{dst}[i] = (float)((double){src}[i] / (double){f32_literal(div)});",
            f"acc = (float)(acc + {dst}[i]);",
            "}",
            f"{self.t(count)} = ({scalar(self.prim(count))})n;",
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
        self.emit(
            "size_t i;",
            f"for (i = 0; i < {n_main}u; i++) {{ {m}[i] = {fill}u; }}",
            f"for (i = 0; i < {n_ext}u; i++) {{ {e}[i] = 0u; }}",
            f"if ({self.s(connected)}) {{",
            f"if ({self.s(count)} == 0 || {c}[0] < {threshold}) {{",
            f"float total = (float)({self.s(volt)} * {mul});",
            f"int64_t fields = (int64_t)(battgen_vcvt_s32(total) / {chunk}) + 1;",  # C division truncates
            f"if (fields >= 1 && fields <= {n_main}) {{",
            "float rest = total;",
            "for (i = 0; i < (size_t)(fields - 1); i++) {",
            f"{m}[i] = {chunk}u;",
            f"rest = (float)(rest - {float(chunk)}f);",
            "}",
            f"{m}[fields - 1] = {self.store_c(main, 'rest')};",
            "} else {",
            f"battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, {self.label(main)});",
            "}",
            "} else {",
            f"size_t slots = (size_t){self.s(count)};",
            f"if (slots > {min(n_cells, n_main + n_ext)}u) {{ slots = {min(n_cells, n_main + n_ext)}u; }}",
            "for (i = 0; i < slots; i++) {",
            f"{scalar(self.prim(main))} v = {self.store_c(main, f'(float)({c}[i] * {mul})')};",
            f"if (i < {n_main}u) {{ {m}[i] = v; }} else {{ {e}[i - {n_main}u] = v; }}",
            "}",
            "}",
            "}",
        )
