"""Encoding and decoding the variable parts of a DroneCAN type: dynamic arrays (with their length
prefix, or the tail array optimisation), large static arrays and nested variable structures."""

from __future__ import annotations

from .....ir import ArrayType, CompositeType, FieldType, PrimitiveType
from ...literals import py_literal, unparenthesized
from .plan import Segment, VarField, is_u8, struct_code
from .segments import SegmentEmitter
from .values import Lines, decode_pattern, encode_value, error, mask, stream, structable_element, unstream


class VariableFieldEmitter(SegmentEmitter):
    def count_put(self, k: str, width: int, out: Lines) -> None:
        out.add(f"acc = (acc << {width}) | {stream(k, width)}")

    def elements_put(self, elem: FieldType, x: str, k: str, elem_tao: str, out: Lines) -> None:
        if is_u8(elem):
            out.add(f'acc = (acc << ({k} << 3)) | int.from_bytes({x}, "big")')
            return
        if isinstance(elem, PrimitiveType):
            e = out.fresh("e")
            word = structable_element(elem)
            if word is not None:
                value = encode_value(word, e, pattern=False)
                code = struct_code(word, pack=True)
                packed = f'_struct.pack(f"<{{{k}}}{code}", *[{value} for {e} in {x}])'
                out.add(f'acc = (acc << ({k} * {elem.bits})) | int.from_bytes({packed}, "big")')
                return
            out.add(f"for {e} in {x}:")
            pat = out.fresh("p")
            out.add(f"    {pat} = {encode_value(elem, e, pattern=True)}")
            out.add(f"    acc = (acc << {elem.bits}) | {stream(pat, elem.bits)}")
            return
        if isinstance(elem, CompositeType):
            e = out.fresh("e")
            if elem_tao == "False":
                out.add(f"for {e} in {x}:")
                out.add(f"    acc = {e}._dc_put(acc, False)")
            else:
                i = out.fresh("i")
                out.add(f"for {i}, {e} in enumerate({x}, 1):")
                out.add(f"    acc = {e}._dc_put(acc, {elem_tao} and {i} == {k})")
            return
        raise ValueError("arrays of arrays are not DSDL v0")

    def var_put(self, item: VarField, expr: str, label: str, tao: str, out: Lines) -> None:
        t = item.type
        if isinstance(t, CompositeType):
            out.add(f"acc = {expr}._dc_put(acc, {tao if self.p.tao_sensitive(t) else 'False'})")
            return
        if isinstance(t, PrimitiveType):
            seg = Segment([], [], [])
            self.p.flatten(seg, t, expr, label)
            self.seg_put(seg, out)
            return
        assert isinstance(t, ArrayType)
        cap = t.capacity or 0
        if t.dynamic and is_u8(t.element):  # bytes: the runtime writes the length and the bytes
            tail = tao if self.p.tao_eligible(t) and tao != "False" else "False"
            out.add(f"acc = _dc.put_bytes(acc, {expr}, {cap}, {tail}, {py_literal(label)})")
            return
        x, k = out.fresh("x"), out.fresh("k")
        out.add(f"{x} = {expr}")
        out.add(f"{k} = len({x})")
        eligible = self.p.tao_eligible(t)
        if t.dynamic:
            out.add(f"if {k} > {cap}:")
            out.add("    raise " + error("EncodeError", f"{label}: length ", f"str({k})", f" exceeds capacity {cap}"))
            width = cap.bit_length()
            if eligible and tao != "False":
                out.add(f"if not {tao}:")
                out.level += 1
                self.count_put(k, width, out)
                out.level -= 1
            else:
                self.count_put(k, width, out)
        else:
            out.add(f"if {k} != {cap}:")
            out.add("    raise " + error("EncodeError", f"{label}: expected {cap} items, got ", f"str({k})"))
        elem_tao = tao if (not eligible and self.p.tao_sensitive(t.element)) else "False"
        self.elements_put(t.element, x, k, elem_tao, out)

    def elements_get(self, elem: FieldType, k: str, target: str, label: str, elem_tao: str, out: Lines) -> None:
        if isinstance(elem, PrimitiveType):
            need = out.fresh("n")
            out.add(f"{need} = {k} * {elem.bits}")
            out.add(f"if rem < {need}:")
            out.add(f"    raise _dc.short({py_literal(label)}, {need}, rem)")
            out.add(f"rem -= {need}")
            word = structable_element(elem)
            if is_u8(elem):
                out.add(f'{target} = ((v >> rem) & ((1 << {need}) - 1)).to_bytes({k}, "big")')
                return
            if word is not None:
                code = struct_code(word, pack=False)
                data = f'((v >> rem) & ((1 << {need}) - 1)).to_bytes({need} >> 3, "big")'
                out.add(f'{target} = list(_struct.unpack(f"<{{{k}}}{code}", {data}))')
                return
            pos, b = out.fresh("q"), out.fresh("b")
            out.add(f"{pos} = rem + {need}")
            out.add(f"{target} = []")
            out.add(f"for _ in range({k}):")
            out.add(f"    {pos} -= {elem.bits}")
            out.add(f"    {b} = (v >> {pos}) & {mask(elem.bits)}")
            value = decode_pattern(elem, unstream(b, elem.bits))
            out.add(f"    {target}.append({value})")
            return
        assert isinstance(elem, CompositeType)
        e, i = out.fresh("e"), out.fresh("i")
        cls = self.class_of(elem)
        out.add(f"{target} = []")
        out.add(f"for {i} in range({k}):")
        flag = "False" if elem_tao == "False" else f"{elem_tao} and {i} == {k} - 1"
        out.add(f"    {e}, rem = {cls}._dc_get(v, rem, {flag})")
        out.add(f"    {target}.append({e})")

    def var_get(self, item: VarField, target: str, label: str, tao: str, out: Lines) -> None:
        t = item.type
        if isinstance(t, CompositeType):
            flag = tao if self.p.tao_sensitive(t) else "False"
            out.add(f"{target}, rem = {self.class_of(t)}._dc_get(v, rem, {flag})")
            return
        if isinstance(t, PrimitiveType):
            seg = Segment([], [], [])
            node = self.p.flatten(seg, t, "", label)
            self.seg_get(seg, out)
            out.add(f"{target} = {self.node_expr(node)}")
            return
        assert isinstance(t, ArrayType)
        cap = t.capacity or 0
        eligible = self.p.tao_eligible(t)
        elem_tao = tao if (not eligible and self.p.tao_sensitive(t.element)) else "False"
        if not t.dynamic:
            self.elements_get(t.element, str(cap), target, label, elem_tao, out)
            return
        if is_u8(t.element):  # bytes: the runtime reads the length and the bytes
            tail = tao if eligible and tao != "False" else "False"
            out.add(f"{target}, rem = _dc.get_bytes(v, rem, {cap}, {tail}, {py_literal(label)})")
            return
        k = out.fresh("k")
        too_long = error("DecodeError", f"{label}: length ", f"str({k})", f" exceeds capacity {cap}")
        if eligible and tao != "False":
            out.add(f"if {tao}:")
            out.level += 1
            self.tao_get(t, k, target, label, too_long, out)
            out.level -= 1
            out.add("else:")
            out.level += 1
        width = cap.bit_length()
        out.add(f"if rem < {width}:")
        out.add(f"    raise _dc.short({py_literal(label + ' (length)')}, {width}, rem)")
        out.add(f"rem -= {width}")
        if width <= 8:  # a count of one byte or less is read as it stands
            out.add(f"{k} = (v >> rem) & {mask(width)}")
        else:
            b = out.fresh("b")
            out.add(f"{b} = (v >> rem) & {mask(width)}")
            out.add(f"{k} = {unparenthesized(unstream(b, width))}")
        out.add(f"if {k} > {cap}:")
        out.add(f"    raise {too_long}")
        self.elements_get(t.element, k, target, label, elem_tao, out)
        if eligible and tao != "False":
            out.level -= 1

    def tao_get(self, t: ArrayType, k: str, target: str, label: str, too_long: str, out: Lines) -> None:
        """The tail array: elements until fewer than 8 bits are left."""
        elem = t.element
        if isinstance(elem, PrimitiveType):
            out.add(f"{k} = rem // {elem.bits}")
            out.add(f"if rem - {k} * {elem.bits} >= 8:")
            out.add("    raise " + error("DecodeError", f"{label}: input ends inside an element"))
            out.add(f"if {k} > {t.capacity}:")
            out.add(f"    raise {too_long}")
            self.elements_get(elem, k, target, label, "False", out)
            return
        assert isinstance(elem, CompositeType)
        e = out.fresh("e")
        out.add(f"{target} = []")
        out.add("while rem >= 8:")
        out.add(f"    if len({target}) == {t.capacity}:")
        out.add(f"        {k} = {t.capacity} + 1")
        out.add(f"        raise {too_long}")
        out.add(f"    {e}, rem = {self.class_of(elem)}._dc_get(v, rem, False)")
        out.add(f"    {target}.append({e})")
