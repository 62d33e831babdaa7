"""Emits the straight-line encode/decode source of one DroneCAN type (see codec_dronecan_plan).

Generated methods per class:
* ``_dc_put(self, acc, tao) -> acc``: append the type's bits to a sentinel-led accumulator int;
* ``_dc_get(cls, v, rem, tao) -> (obj, rem)``: read it from payload int ``v`` with ``rem`` bits left;
* ``encode`` / ``decode``: the public top level, which packs a leading fixed run with one
  ``struct`` call straight from or into the bytes, and a byte-aligned tail array by slicing.
"""

from __future__ import annotations

from .....ir import ArrayType, CastMode, CompositeType, FieldType, Message, PrimitiveKind, PrimitiveType
from ...literals import py_literal
from .plan import Item, Node, Piece, Planner, Segment, Unit, VarField, is_u8, plan_units, struct_code
from .values import (
    Lines,
    clamp,
    decode_pattern,
    encode_value,
    error,
    mask,
    needs_name,
    stream,
    structable_element,
    unstream,
)


class MessageEmitter:
    def __init__(self, planner: Planner, msg: Message, cls: str, tag: str, factory: dict[str, str]) -> None:
        self.p = planner
        self.msg = msg
        self.cls = cls
        self.tag = tag  # prefix of module-level names
        self.factory = factory
        self.module_code: list[str] = []
        self.constants: dict[str, str] = {}
        self.idents = planner.idents(msg)
        self.union_attr = "union_field"

    # -- module-level helpers ---------------------------------------------------------------

    def module_value(self, source: str) -> str:
        """A module-level constant (struct, table) holding ``source``; shared when equal."""
        name = self.constants.get(source)
        if name is None:
            name = f"_DC_{self.tag}_{len(self.constants) + 1}"
            self.constants[source] = name
            self.module_code.append(f"{name} = {source}")
        return name

    def struct_name(self, fmt: str) -> str:
        return self.module_value(f"struct.Struct({py_literal(fmt)})")

    def cut_table(self, seg: Segment) -> str:
        rows = [(leaf.offset + leaf.bits, leaf.label) for leaf in seg.leaves]
        return self.module_value(py_literal(tuple(rows)))

    def class_of(self, t: CompositeType) -> str:
        return self.factory[t.name]

    # -- segments: encoding ---------------------------------------------------------------

    def seg_checks(self, seg: Segment, out: Lines) -> None:
        for expr, n, label in seg.checks:
            out.add(f"if len({expr}) != {n}:")
            out.add("    raise " + error("EncodeError", f"{label}: expected {n} items, got ", f"str(len({expr}))"))

    def seg_pack_args(self, seg: Segment, units: list[Unit], pieces: dict[int, list[Piece]], out: Lines) -> list[str]:
        """Lines computing leaf values; returns the struct.pack arguments."""
        self.seg_checks(seg, out)
        values = self.float16_batch(seg, out)
        for idx, leaf in enumerate(seg.leaves):
            if leaf.type.kind is PrimitiveKind.VOID or idx in values:
                continue
            raw = leaf.enc
            if leaf.nbytes:
                values[idx] = raw
                continue
            group = not leaf.structable
            if needs_name(leaf.type) or group:
                name = out.fresh("r")
                out.add(f"{name} = {raw}")
                raw = name
            value = encode_value(leaf.type, raw, pattern=group)
            if group:
                name = out.fresh("p")
                out.add(f"{name} = {value}")
                value = name
            values[idx] = value
        by_unit: dict[int, list[str]] = {}
        for idx, runs in pieces.items():
            leaf = seg.leaves[idx]
            for pc in runs:
                x = values[idx]
                if pc.src == 0 and pc.size == leaf.bits:
                    term = x
                else:
                    term = f"(({x} >> {pc.src}) & {mask(pc.size)})" if pc.src else f"({x} & {mask(pc.size)})"
                by_unit.setdefault(pc.unit, []).append(f"({term} << {pc.dst})" if pc.dst else term)
        args = []
        for k, u in enumerate(units):
            if u.group:
                terms = by_unit.get(k, [])
                args.append(" | ".join(terms) if terms else "0")
            elif u.leaf is not None:
                args.append(values[seg.leaves.index(u.leaf)])
        return args

    def float16_batch(self, seg: Segment, out: Lines) -> dict[int, str]:
        """float16 bits of several fields at once: one struct round trip gives every float32
        pattern, a normal half is then a subtraction and a shift (the rest go to the runtime)."""
        halves = [
            (idx, leaf)
            for idx, leaf in enumerate(seg.leaves)
            if leaf.type.kind is PrimitiveKind.FLOAT and leaf.type.bits == 16 and not leaf.nbytes
        ]
        if len(halves) < 2:
            return {}
        clamped = []
        for _, leaf in halves:
            raw = out.fresh("r")
            out.add(f"{raw} = {leaf.enc}")
            if leaf.type.cast is CastMode.SATURATED:
                clamped.append(clamp(raw, "-65504.0", "65504.0"))
            else:
                clamped.append(clamp(raw, "-65504.0", "65504.0", "-_dc.INF", "_dc.INF"))
        n = len(halves)
        words = [out.fresh("g") for _ in halves]
        floats, ints = self.struct_name(f"<{n}f"), self.struct_name(f"<{n}I")
        out.add(f"{', '.join(words)} = {ints}.unpack({floats}.pack({', '.join(clamped)}))")
        values: dict[int, str] = {}
        for (idx, _), g in zip(halves, words, strict=True):
            h = out.fresh("h")
            out.add(f"{h} = (")  # positive normal, negative normal, anything else
            out.add(f"    (({g} - 0x37FFF000) >> 13)")
            out.add(f"    if 0x38800000 <= {g} < 0x477FF000")
            out.add(f"    else ((({g} - 0xB7FFF000) >> 13) | 0x8000")
            out.add(f"          if 0xB8800000 <= {g} < 0xC77FF000 else _dc.f16bits({g}))")
            out.add(")")
            values[idx] = h
        return values

    def seg_bytes(self, seg: Segment, out: Lines) -> str:
        """Lines packing a segment; returns the expression of its bytes (zero padded)."""
        units, pieces = plan_units(seg)
        args = self.seg_pack_args(seg, units, pieces, out)
        fmt = "<" + "".join(u.pack for u in units)
        name = self.struct_name(fmt)
        return f"{name}.pack({', '.join(args)})"

    def seg_put(self, seg: Segment, out: Lines) -> None:
        """Append a segment to ``acc``."""
        if seg.bits == 0:
            self.seg_checks(seg, out)
            return
        live = [leaf for leaf in seg.leaves if leaf.type.kind is not PrimitiveKind.VOID]
        if not live:
            out.add(f"acc <<= {seg.bits}")
            return
        if len(seg.leaves) == 1 and seg.bits <= 8 and not live[0].nbytes:
            leaf = live[0]
            raw = leaf.enc
            if needs_name(leaf.type):
                raw = out.fresh("r")
                out.add(f"{raw} = {leaf.enc}")
            out.add(f"acc = (acc << {seg.bits}) | {encode_value(leaf.type, raw, pattern=True)}")
            return
        data = self.seg_bytes(seg, out)
        pad = -seg.bits % 8
        shifted = f"(int.from_bytes({data}, 'big') >> {pad})" if pad else f"int.from_bytes({data}, 'big')"
        out.add(f"acc = (acc << {seg.bits}) | {shifted}")

    # -- segments: decoding ---------------------------------------------------------------

    def seg_unpack(self, seg: Segment, out: Lines, source: str) -> None:
        """Lines unpacking a segment from ``source`` (bytes expression or 'from:<data>'); sets leaf vars."""
        units, pieces = plan_units(seg)
        fmt = "<" + "".join(u.unpack for u in units)
        unit_vars: dict[int, str] = {}
        names = []
        for k, u in enumerate(units):
            if u.pack.endswith("x"):
                continue
            var = out.fresh("u")
            unit_vars[k] = var
            names.append(var)
            if u.leaf is not None:
                u.leaf.var = var
        if names:
            st = self.struct_name(fmt)
            call = f"{st}.unpack_from({source[5:]})" if source.startswith("from:") else f"{st}.unpack({source})"
            target = ", ".join(names) + ("," if len(names) == 1 else "")
            out.add(f"{target} = {call}")
        for idx, runs in pieces.items():
            leaf = seg.leaves[idx]
            parts = []
            for pc in runs:
                u_var = unit_vars[pc.unit]
                ubits = units[pc.unit].size * 8
                term = f"({u_var} >> {pc.dst})" if pc.dst else u_var
                if pc.dst + pc.size < ubits:
                    term = f"({term} & {mask(pc.size)})"
                parts.append(f"({term} << {pc.src})" if pc.src else term)
            bits = parts[0] if len(parts) == 1 else "(" + " | ".join(parts) + ")"
            var = out.fresh("x")
            out.add(f"{var} = {decode_pattern(leaf.type, bits)}")
            leaf.var = var

    def seg_get(self, seg: Segment, out: Lines) -> None:
        """Read a segment from ``v`` with ``rem`` bits left."""
        if seg.bits == 0:
            return
        out.add(f"if rem < {seg.bits}:")
        out.add(f"    raise _dc.cut({self.cut_table(seg)}, rem)")
        out.add(f"rem -= {seg.bits}")
        live = [leaf for leaf in seg.leaves if leaf.type.kind is not PrimitiveKind.VOID]
        if not live:
            return
        if len(seg.leaves) == 1 and seg.bits <= 8 and not live[0].nbytes:
            var = out.fresh("x")
            out.add(f"{var} = {decode_pattern(live[0].type, f'((v >> rem) & {mask(seg.bits)})')}")
            live[0].var = var
            return
        nb = (seg.bits + 7) // 8
        pad = -seg.bits % 8
        chunk = f"((v >> rem) & {mask(seg.bits)})"
        if pad:
            chunk = f"({chunk} << {pad})"
        self.seg_unpack(seg, out, f"{chunk}.to_bytes({nb}, 'big')")

    def node_expr(self, node: Node) -> str:
        if node.leaf is not None:
            return node.leaf.var
        inner = ", ".join(self.node_expr(n) for n in node.items)
        if node.factory:
            return f"{node.factory}({inner})"
        if node.as_bytes:
            return f"bytes(({inner}{',' if len(node.items) == 1 else ''}))"
        return f"[{inner}]"

    # -- variable fields ------------------------------------------------------------------

    def count_put(self, k: str, width: int, out: Lines) -> None:
        out.add(f"acc = (acc << {width}) | {stream(k, width)}")

    def elements_put(self, elem: FieldType, x: str, k: str, elem_tao: str, out: Lines) -> None:
        if is_u8(elem):
            out.add(f"acc = (acc << ({k} << 3)) | int.from_bytes({x}, 'big')")
            return
        if isinstance(elem, PrimitiveType):
            e = out.fresh("e")
            word = structable_element(elem)
            if word is not None:
                value = encode_value(word, e, pattern=False)
                code = struct_code(word, pack=True)
                packed = f"struct.pack(f'<{{{k}}}{code}', *[{value} for {e} in {x}])"
                out.add(f"acc = (acc << ({k} * {elem.bits})) | int.from_bytes({packed}, 'big')")
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
                out.add(f"{target} = ((v >> rem) & ((1 << {need}) - 1)).to_bytes({k}, 'big')")
                return
            if word is not None:
                code = struct_code(word, pack=False)
                data = f"((v >> rem) & ((1 << {need}) - 1)).to_bytes({need} >> 3, 'big')"
                out.add(f"{target} = list(struct.unpack(f'<{{{k}}}{code}', {data}))")
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
        b = out.fresh("b")
        out.add(f"{b} = (v >> rem) & {mask(width)}")
        out.add(f"{k} = {unstream(b, width)}")
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

    # -- whole structures -----------------------------------------------------------------

    def annotation(self, t: FieldType) -> str | None:
        if isinstance(t, ArrayType):
            return "bytes" if is_u8(t.element) else "list[Any]"
        return None

    def items(self, base: str) -> list[Item]:
        return self.p.items(self.msg, self.cls, self.idents, base)

    def body_put(self, items: list[Item], out: Lines) -> None:
        for item in items:
            if isinstance(item, Segment):
                self.seg_put(item, out)
            else:
                label = f"{self.cls}.{item.field_name}"
                self.var_put(item, f"self.{item.ident}", label, "tao" if item.last else "False", out)

    def body_get(self, items: list[Item], out: Lines) -> dict[int, str]:
        """Decode items; returns field index -> value expression."""
        values: dict[int, str] = {}
        for item in items:
            if isinstance(item, Segment):
                self.seg_get(item, out)
                for index, node in item.nodes:
                    values[index] = self.node_expr(node)
            else:
                values[item.index] = f"f{item.index}"
                label = f"{self.cls}.{item.field_name}"
                self.var_get(item, f"f{item.index}", label, "tao" if item.last else "False", out)
        return values

    def declare(self, items: list[Item], out: Lines) -> None:
        for item in items:
            if isinstance(item, VarField):
                ann = self.annotation(item.type)
                if ann is not None:
                    out.add(f"f{item.index}: {ann}")

    def construct(self, values: dict[int, str]) -> str:
        args = [values[i] for i, f in enumerate(self.msg.fields) if not f.is_padding]
        return f"cls({', '.join(args)})"

    def trailing(self, out: Lines) -> None:
        out.add("if rem >= 8:")
        out.add(
            "    raise "
            + error("DecodeError", f"{self.cls}: ", "str(rem >> 3)", " byte(s) beyond the end of the message")
        )

    def method_put(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            self.union_put(out)
        else:
            self.body_put(self.items("self"), out)
        out.add("return acc")
        return "def _dc_put(self, acc: int, tao: bool) -> int:\n" + out.text(1)

    def method_get(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            self.union_get(out)
        else:
            items = self.items("self")
            self.declare(items, out)
            values = self.body_get(items, out)
            out.add(f"return {self.construct(values)}, rem")
        head = f"@classmethod\ndef _dc_get(cls, v: int, rem: int, tao: bool) -> tuple[{self.cls}, int]:\n"
        return head + out.text(1)

    def union_fields(self) -> list[tuple[int, str]]:
        return [(i, self.idents[i]) for i, f in enumerate(self.msg.fields)]

    def tag_bits(self) -> int:
        return max(len(self.msg.fields) - 1, 1).bit_length()

    def union_put(self, out: Lines) -> None:
        bits = self.tag_bits()
        out.add(f"u = self.{self.union_attr}")
        for n, (i, ident) in enumerate(self.union_fields()):
            out.add(f"{'if' if n == 0 else 'elif'} u == {py_literal(ident)}:")
            out.level += 1
            out.add(f"acc = (acc << {bits}) | {n}" if n else f"acc <<= {bits}")
            f = self.msg.fields[i]
            item = VarField(i, f.name, ident, f.type, True)
            self.branch_put(item, out)
            out.level -= 1
        out.add("else:")
        out.add(
            "    raise "
            + error("EncodeError", f"{self.cls}.{self.union_attr}: ", "repr(u)", f" is not a field of {self.cls}")
        )

    def branch_put(self, item: VarField, out: Lines) -> None:
        label = f"{self.cls}.{item.field_name}"
        expr = f"self.{item.ident}"
        if self.p.fixed(item.type):
            seg = Segment([], [], [])
            self.p.flatten(seg, item.type, expr, label)
            self.seg_put(seg, out)
        else:
            self.var_put(item, expr, label, "tao", out)

    def union_get(self, out: Lines) -> None:
        bits = self.tag_bits()
        out.add(f"if rem < {bits}:")
        out.add(f"    raise _dc.short({py_literal(self.cls + ' (union tag)')}, {bits}, rem)")
        out.add(f"rem -= {bits}")
        out.add(f"t = (v >> rem) & {mask(bits)}")
        for n, (i, ident) in enumerate(self.union_fields()):
            f = self.msg.fields[i]
            out.add(f"{'if' if n == 0 else 'elif'} t == {n}:")
            out.level += 1
            label = f"{self.cls}.{f.name}"
            target = out.fresh("w")
            if self.p.fixed(f.type):
                seg = Segment([], [], [])
                node = self.p.flatten(seg, f.type, "", label)
                self.seg_get(seg, out)
                out.add(f"{target} = {self.node_expr(node)}")
            else:
                ann = self.annotation(f.type)
                if ann is not None:
                    out.add(f"{target}: {ann}")
                self.var_get(VarField(i, f.name, ident, f.type, True), target, label, "tao", out)
            out.add(f"return cls({ident}={target}, {self.union_attr}={py_literal(ident)}), rem")
            out.level -= 1
        count = len(self.msg.fields)
        out.add("raise " + error("DecodeError", f"{self.cls}: union tag ", "str(t)", f" is not one of 0..{count - 1}"))

    # -- public top level -----------------------------------------------------------------

    def tail_fast(self, items: list[Item]) -> VarField | None:
        """The last field, when it is a byte-aligned tail array that can be sliced directly."""
        if not items or not isinstance(items[-1], VarField):
            return None
        if len(items) > 2 or (len(items) == 2 and (not isinstance(items[0], Segment) or items[0].bits % 8)):
            return None
        item = items[-1]
        t = item.type
        if not (isinstance(t, ArrayType) and item.last and self.p.tao_eligible(t)):
            return None
        if is_u8(t.element) or structable_element(t.element) is not None:
            return item
        return None

    def method_encode(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            out.add("return _dc.finish(self._dc_put(1, tao))")
        else:
            items = self.items("self")
            head_seg = items[0] if items and isinstance(items[0], Segment) and items[0].bits else None
            rest = items[1:] if head_seg is not None else items
            if head_seg is not None:
                out.add(f"head = {self.seg_bytes(head_seg, out)}")
                if not rest:
                    out.add("return head")
                    return self.wrap_encode(out)
            tail = self.tail_fast(items)
            if tail is not None:
                self.tail_put(tail, "head" if head_seg is not None else "b''", out)
            if head_seg is not None:
                pad = -head_seg.bits % 8
                bits = f"(int.from_bytes(head, 'big') >> {pad})" if pad else "int.from_bytes(head, 'big')"
                out.add(f"acc = {hex(1 << head_seg.bits)} | {bits}")
            else:
                out.add("acc = 1")
            self.body_put(rest, out)
            out.add("return _dc.finish(acc)")
        return self.wrap_encode(out)

    def wrap_encode(self, out: Lines) -> str:
        doc = '    """The DroneCAN payload; ``tao=False`` turns the tail array optimisation off (CAN FD)."""\n'
        return "def encode(self, *, tao: bool = True) -> bytes:\n" + doc + out.text(1)

    def tail_put(self, item: VarField, head: str, out: Lines) -> None:
        t = item.type
        assert isinstance(t, ArrayType)
        label = f"{self.cls}.{item.field_name}"
        out.add("if tao:")
        out.level += 1
        x = out.fresh("x")
        out.add(f"{x} = self.{item.ident}")
        out.add(f"if len({x}) > {t.capacity}:")
        out.add(
            "    raise "
            + error("EncodeError", f"{label}: length ", f"str(len({x}))", f" exceeds capacity {t.capacity}")
        )
        if is_u8(t.element):
            out.add(f"return {head} + bytes({x})")
        else:
            word = structable_element(t.element)
            assert word is not None
            e = out.fresh("e")
            value = encode_value(word, e, pattern=False)
            code = struct_code(word, pack=True)
            out.add(f"return {head} + struct.pack(f'<{{len({x})}}{code}', *[{value} for {e} in {x}])")
        out.level -= 1

    def method_decode(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            out.add("obj, rem = cls._dc_get(int.from_bytes(data, 'big'), len(data) << 3, tao)")
            self.trailing(out)
            out.add("return obj")
            return self.wrap_decode(out)
        items = self.items("self")
        self.declare(items, out)
        head_seg = items[0] if items and isinstance(items[0], Segment) and items[0].bits else None
        rest = items[1:] if head_seg is not None else items
        values: dict[int, str] = {}
        out.add("n = len(data)")
        head_bits = 0
        if head_seg is not None:
            head_bits = head_seg.bits
            nb = (head_bits + 7) // 8
            out.add(f"if n < {nb}:")
            out.add(f"    raise _dc.cut({self.cut_table(head_seg)}, n << 3)")
            self.seg_unpack(head_seg, out, "from:data")
            for index, node in head_seg.nodes:
                values[index] = self.node_expr(node)
            if not rest:
                out.add(f"if n > {nb}:")
                out.add(
                    "    raise "
                    + error("DecodeError", f"{self.cls}: ", f"str(n - {nb})", " byte(s) beyond the end of the message")
                )
                out.add(f"return {self.construct(values)}")
                return self.wrap_decode(out)
        tail = self.tail_fast(items)
        if tail is not None:
            values[tail.index] = f"f{tail.index}"
            self.tail_get(tail, (head_bits + 7) // 8, out)
            out.add(f"    return {self.construct(values)}")
        out.add("v = int.from_bytes(data, 'big')")
        out.add(f"rem = (n << 3) - {head_bits}" if head_bits else "rem = n << 3")
        values.update(self.body_get(rest, out))
        self.trailing(out)
        out.add(f"return {self.construct(values)}")
        return self.wrap_decode(out)

    def tail_get(self, item: VarField, start: int, out: Lines) -> None:
        t = item.type
        assert isinstance(t, ArrayType)
        label = f"{self.cls}.{item.field_name}"
        target = f"f{item.index}"
        out.add("if tao:")
        out.level += 1
        k = out.fresh("k")
        too_long = error("DecodeError", f"{label}: length ", f"str({k})", f" exceeds capacity {t.capacity}")
        if is_u8(t.element):
            out.add(f"{target} = bytes(data[{start}:])" if start else f"{target} = bytes(data)")
            out.add(f"{k} = len({target})")
            out.add(f"if {k} > {t.capacity}:")
            out.add(f"    raise {too_long}")
        else:
            word = structable_element(t.element)
            assert word is not None
            size = word.bits // 8
            out.add(f"{k}, extra = divmod(n - {start}, {size})")
            out.add("if extra:")
            out.add("    raise " + error("DecodeError", f"{label}: input ends inside an element"))
            out.add(f"if {k} > {t.capacity}:")
            out.add(f"    raise {too_long}")
            code = struct_code(word, pack=False)
            out.add(f"{target} = list(struct.unpack_from(f'<{{{k}}}{code}', data, {start}))")
        out.level -= 1

    def wrap_decode(self, out: Lines) -> str:
        doc = '    """Read a DroneCAN payload; ``tao=False`` for CAN FD. Raises DecodeError naming the field."""\n'
        head = f"@classmethod\ndef decode(cls, data: bytes, *, tao: bool = True) -> {self.cls}:\n"
        return head + doc + out.text(1)
