"""Emits the straight-line encode/decode source of one DroneCAN type (see :mod:`.plan`).

Generated methods per class, one encoding and one decoding:
* ``_dc_head(self) -> bytes``: the fixed fields that open the payload, packed with one ``struct`` call;
* ``_dc_from_head(cls, data, *after) -> obj``: the same fields read back from bytes with one ``struct`` call,
  into a new instance with the values of the fields after them;
* ``_dc_put(self, acc, tao) -> acc``: append the type's bits to a sentinel-led accumulator int (starting
  from ``_dc_head``);
* ``_dc_get(cls, v, rem, tao) -> (obj, rem)``: read it from payload int ``v`` with ``rem`` bits left
  (starting from ``_dc_from_head``);
* ``encode`` / ``decode``: the public top level. A type of fixed fields alone is its head; one ending in a
  byte-aligned tail array sent with TAO is its head and the array's bytes, sliced; anything else is
  ``_dc_put`` finished or ``_dc_get`` through ``_dc.read``.

Fixed runs of fields are :mod:`.segments`, the variable parts :mod:`.variable`; this module puts
them together into whole structures and unions.
"""

from __future__ import annotations

from .....ir import ArrayType, FieldType
from ...literals import py_literal
from .plan import Item, Segment, VarField, is_u8, struct_code
from .values import Lines, encode_value, error, mask, structable_element
from .variable import VariableFieldEmitter


class MessageEmitter(VariableFieldEmitter):
    def annotation(self, t: FieldType) -> str | None:
        if isinstance(t, ArrayType):
            return "bytes" if is_u8(t.element) else "list[_Any]"
        return None

    def items(self, base: str) -> list[Item]:
        return self.p.items(self.msg, self.cls, self.idents, base)

    def body_put(self, items: list[Item], out: Lines, tao: str = "tao") -> None:
        """Encode items; ``tao`` is what the last of them is told of the tail array optimisation."""
        for item in items:
            if isinstance(item, Segment):
                self.seg_put(item, out)
            else:
                label = f"{self.cls}.{item.field_name}"
                self.var_put(item, f"self.{item.ident}", label, tao if item.last else "False", out)

    def body_get(self, items: list[Item], out: Lines, tao: str = "tao") -> dict[int, str]:
        """Decode items; returns field index -> value expression."""
        values: dict[int, str] = {}
        for item in items:
            if isinstance(item, Segment):
                self.seg_get(item, out)
                for index, node in item.nodes:
                    values[index] = self.node_expr(node)
            else:
                label = f"{self.cls}.{item.field_name}"
                values[item.index] = out.field_var(item.index, label)
                self.var_get(item, values[item.index], label, tao if item.last else "False", out)
        return values

    def declare(self, items: list[Item], out: Lines) -> None:
        for item in items:
            t = item.type if isinstance(item, VarField) else None
            if isinstance(t, ArrayType) and t.dynamic and is_u8(t.element):
                continue  # read by _dc.get_bytes, typed there
            if isinstance(item, VarField):
                ann = self.annotation(item.type)
                if ann is not None:
                    out.add(f"{out.field_var(item.index, f'{self.cls}.{item.field_name}')}: {ann}")

    def construct(self, values: dict[int, str]) -> str:
        args = [values[i] for i, f in enumerate(self.msg.fields) if not f.is_padding]
        return f"cls({', '.join(args)})"

    @staticmethod
    def head_segment(items: list[Item]) -> Segment | None:
        """The run of fixed fields that opens the payload, when there is one."""
        return items[0] if items and isinstance(items[0], Segment) and items[0].bits else None

    def method_head(self) -> str | None:
        """``_dc_head``: the opening fixed fields packed into bytes, the one packing ``encode`` and
        ``_dc_put`` share (None for a union, or a type that opens with a field of varying size)."""
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            return None
        head = self.head_segment(self.items("self"))
        if head is None:
            return None
        out = Lines()
        out.add(f"return {self.seg_bytes(head, out)}")
        doc = f'    """Bits 0-{head.bits - 1} (the fixed fields that open the payload) as bytes, zero padded."""\n'
        return "def _dc_head(self) -> bytes:\n" + doc + out.text(1)

    def method_from_head(self) -> str | None:
        """``_dc_from_head``: a new instance of the opening fixed fields read back from bytes and of the values of
        the fields after them, the one reading ``decode`` and ``_dc_get`` share (None where there is no
        ``_dc_head``). Those values are parameters of their own, as ``*rest`` would cost the decoder a tenth."""
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            return None
        items = self.items("self")
        head = self.head_segment(items)
        if head is None:
            return None
        out = Lines()
        after = [
            out.field_var(i, f"{self.cls}.{f.name}")
            for i, f in enumerate(self.msg.fields)
            if not f.is_padding and i not in dict(head.nodes)
        ]
        self.seg_unpack(head, out, "from:data")
        values = [self.node_expr(node) for _, node in head.nodes]
        if all(v.isidentifier() for v in values):
            out.add(f"return cls({', '.join(values + after)})")
        else:  # a field assembled in place is named beside it
            out.add("return cls(")
            for (index, _), value in zip(head.nodes, values, strict=True):
                name = self.msg.fields[index].name
                # a DSDL field name is an identifier (the DSDL frontend keeps them so): safe in a comment
                out.add(f"    {value}," if value.isidentifier() else f"    {value},  # {name}")
            for name in after:
                out.add(f"    {name},")
            out.add(")")
        what = ",\n    and of the values of the fields after them" if after else ""
        bits = f"bits 0-{head.bits - 1} (the fixed fields that open the payload)"
        doc = f'    """A new instance of {bits} read from ``data``{what}."""\n'
        params = ", ".join(["data: bytes", *(f"{name}: _Any" for name in after)])
        return f"@classmethod\ndef _dc_from_head(cls, {params}) -> {self.cls}:\n" + doc + out.text(1)

    def method_put(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            self.union_put(out)
        else:
            items = self.items("self")
            head = self.head_segment(items)
            if head is not None:
                pad = -head.bits % 8
                bits = (
                    '(int.from_bytes(self._dc_head(), "big") >> ' + f"{pad})"
                    if pad
                    else 'int.from_bytes(self._dc_head(), "big")'
                )
                out.add(f"acc = (acc << {head.bits}) | {bits}")
                items = items[1:]
            self.body_put(items, out)
        out.add("return acc")
        return "def _dc_put(self, acc: int, tao: bool) -> int:\n" + out.text(1)

    def method_get(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            self.union_get(out)
        else:
            items = self.items("self")
            self.declare(items, out)
            head = self.head_segment(items)
            first = ""
            if head is not None:
                nb, pad = (head.bits + 7) // 8, -head.bits % 8
                chunk = f"((v >> rem) & {mask(head.bits)})"
                out.add(f"if rem < {head.bits}:")
                out.add(f"    raise _dc.cut({self.cut_table(head)}, rem)")
                out.add(f"rem -= {head.bits}")
                out.add(f'head = {f"({chunk} << {pad})" if pad else chunk}.to_bytes({nb}, "big")')
                items, first = items[1:], "head"
            values = self.body_get(items, out)
            if first:
                args = [values[i] for i, f in enumerate(self.msg.fields) if not f.is_padding and i in values]
                out.add(f"return cls._dc_from_head({', '.join([first, *args])}), rem")
            else:
                out.add(f"return {self.construct(values)}, rem")
        signature = f"@classmethod\ndef _dc_get(cls, v: int, rem: int, tao: bool) -> tuple[{self.cls}, int]:\n"
        return signature + out.text(1)

    def union_fields(self) -> list[tuple[int, str]]:
        return [(i, self.idents[i]) for i, f in enumerate(self.msg.fields)]

    def tag_bits(self) -> int:
        return max(len(self.msg.fields) - 1, 1).bit_length()

    def union_put(self, out: Lines) -> None:
        bits = self.tag_bits()
        out.add(f"u = self.{self.union_attr}")
        for n, (i, ident) in enumerate(self.union_fields()):
            f = self.msg.fields[i]
            out.add(f"{'if' if n == 0 else 'elif'} u == {py_literal(f.name)}:")
            out.level += 1
            held = out.fresh("x")
            out.add(f"{held} = self.{ident}")
            out.add(f"if {held} is None:")
            out.add("    raise " + error("EncodeError", f"{self.cls}.{f.name}: the selected branch holds None"))
            out.add(f"acc = (acc << {bits}) | {n}" if n else f"acc <<= {bits}")
            item = VarField(i, f.name, ident, f.type, True)
            self.branch_put(item, held, out)
            out.level -= 1
        out.add("else:")
        out.add(
            "    raise "
            + error("EncodeError", f"{self.cls}.{self.union_attr}: ", "repr(u)", f" is not a field of {self.cls}")
        )

    def branch_put(self, item: VarField, expr: str, out: Lines) -> None:
        label = f"{self.cls}.{item.field_name}"
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
            out.add(f"return cls({ident}={target}), rem")
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
        """``encode``: the bit accumulator of ``_dc_put``, the one encoding; a type of fixed fields alone, or
        ending in a byte-aligned tail array sent with TAO, is returned as the packed head (and the array's
        bytes) without it."""
        out = Lines()
        items = [] if self.msg.dronecan is not None and self.msg.dronecan.union else self.items("self")
        head_seg = self.head_segment(items)
        if head_seg is not None and len(items) == 1:
            out.add("return self._dc_head()")
            return self.wrap_encode(out)
        tail = self.tail_fast(items)
        if tail is not None:  # returns when tao is true: what follows runs only without it
            self.tail_put(tail, "self._dc_head()" if head_seg is not None else 'b""', out)
        out.add(f"return _dc.finish(self._dc_put(1, {'False' if tail is not None else 'tao'}))")
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
        x = out.named(label)
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
            out.add(f'return {head} + _struct.pack(f"<{{len({x})}}{code}", *[{value} for {e} in {x}])')
        out.level -= 1

    def method_decode(self) -> str:
        """``decode``: a type of fixed fields alone is read by ``_dc_from_head``; one ending in a byte-aligned
        tail array sent with TAO by it and a slice; anything else by ``_dc_get`` (``_dc.read``)."""
        out = Lines()
        union = self.msg.dronecan is not None and self.msg.dronecan.union
        items = [] if union else self.items("self")
        head_seg = self.head_segment(items)
        tail = self.tail_fast(items)
        if tail is None and (head_seg is None or len(items) > 1):
            out.add("return _dc.read(cls, data, tao)")
            return self.wrap_decode(out)
        out.add("n = len(data)")
        nb = 0
        if head_seg is not None:
            nb = (head_seg.bits + 7) // 8
            out.add(f"if n < {nb}:")
            out.add(f"    raise _dc.cut({self.cut_table(head_seg)}, n << 3)")
        if tail is None:
            out.add(f"if n > {nb}:")
            out.add(f"    raise _dc.beyond({py_literal(self.cls)}, n - {nb})")
            out.add("return cls._dc_from_head(data)")
            return self.wrap_decode(out)
        out.add("if tao:")
        out.level += 1
        value = self.tail_get(tail, nb, out)
        out.add(f"return cls._dc_from_head(data, {value})" if head_seg is not None else f"return cls({value})")
        out.level -= 1
        # without TAO the array has its length prefix: the bit reader, as when the type is nested
        out.add("return _dc.read(cls, data, False)")
        return self.wrap_decode(out)

    def tail_get(self, item: VarField, start: int, out: Lines) -> str:
        """Lines checking the tail array that fills the payload from byte ``start``; returns its value."""
        t = item.type
        assert isinstance(t, ArrayType)
        label = f"{self.cls}.{item.field_name}"
        if is_u8(t.element):
            count = f"n - {start}" if start else "n"
            out.add(f"if n > {start + (t.capacity or 0)}:")
            out.add(
                "    raise "
                + error("DecodeError", f"{label}: length ", f"str({count})", f" exceeds capacity {t.capacity}")
            )
            return f"bytes(data[{start}:])" if start else "bytes(data)"
        word = structable_element(t.element)
        assert word is not None
        k = out.named(label, "count")
        out.add(f"{k}, extra = divmod(n - {start}, {word.bits // 8})")
        out.add("if extra:")
        out.add("    raise " + error("DecodeError", f"{label}: input ends inside an element"))
        out.add(f"if {k} > {t.capacity}:")
        out.add(
            "    raise " + error("DecodeError", f"{label}: length ", f"str({k})", f" exceeds capacity {t.capacity}")
        )
        return f'list(_struct.unpack_from(f"<{{{k}}}{struct_code(word, pack=False)}", data, {start}))'

    def wrap_decode(self, out: Lines) -> str:
        doc = '    """Read a DroneCAN payload; ``tao=False`` for CAN FD. Raises DecodeError naming the field."""\n'
        head = f"@classmethod\ndef decode(cls, data: bytes, *, tao: bool = True) -> {self.cls}:\n"
        return head + doc + out.text(1)
