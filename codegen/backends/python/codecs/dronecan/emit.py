"""Emits the straight-line encode/decode source of one DroneCAN type (see :mod:`.plan`).

Generated methods per class:
* ``_dc_head(self) -> bytes``: the fixed fields that open the payload, packed with one ``struct`` call;
* ``_dc_put(self, acc, tao) -> acc``: append the type's bits to a sentinel-led accumulator int (the
  one encoding: it starts from ``_dc_head``);
* ``_dc_get(cls, v, rem, tao) -> (obj, rem)``: read it from payload int ``v`` with ``rem`` bits left;
* ``encode`` / ``decode``: the public top level; ``encode`` is ``_dc_put`` finished, except that a
  byte-aligned tail array sent with TAO is appended to ``_dc_head``'s bytes by slicing; ``decode``
  unpacks the opening fixed run with one ``struct`` call straight from the bytes.

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
            if isinstance(item, VarField):
                ann = self.annotation(item.type)
                if ann is not None:
                    out.add(f"{out.field_var(item.index, f'{self.cls}.{item.field_name}')}: {ann}")

    def construct(self, values: dict[int, str]) -> str:
        args = [values[i] for i, f in enumerate(self.msg.fields) if not f.is_padding]
        return f"cls({', '.join(args)})"

    def trailing(self, out: Lines) -> None:
        out.add("if rem >= 8:")
        out.add(
            "    raise "
            + error("DecodeError", f"{self.cls}: ", "str(rem >> 3)", " byte(s) beyond the end of the message")
        )

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
            out.add(f'return {head} + _struct.pack(f"<{{len({x})}}{code}", *[{value} for {e} in {x}])')
        out.level -= 1

    def method_decode(self) -> str:
        out = Lines()
        if self.msg.dronecan is not None and self.msg.dronecan.union:
            out.add('obj, rem = cls._dc_get(int.from_bytes(data, "big"), len(data) << 3, tao)')
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
        if tail is not None:  # returns when tao is true: what follows runs only without it
            values[tail.index] = out.field_var(tail.index, f"{self.cls}.{tail.field_name}")
            self.tail_get(tail, (head_bits + 7) // 8, out)
            out.add(f"    return {self.construct(values)}")
            # without TAO the array has its length prefix: the bit reader, as when the type is nested
            out.add('obj, rem = cls._dc_get(int.from_bytes(data, "big"), n << 3, False)')
            self.trailing(out)
            out.add("return obj")
            return self.wrap_decode(out)
        out.add('v = int.from_bytes(data, "big")')
        out.add(f"rem = (n << 3) - {head_bits}" if head_bits else "rem = n << 3")
        values.update(self.body_get(rest, out))
        self.trailing(out)
        out.add(f"return {self.construct(values)}")
        return self.wrap_decode(out)

    def tail_get(self, item: VarField, start: int, out: Lines) -> None:
        t = item.type
        assert isinstance(t, ArrayType)
        label = f"{self.cls}.{item.field_name}"
        target = out.field_var(item.index, label)
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
            out.add(f'{target} = list(_struct.unpack_from(f"<{{{k}}}{code}", data, {start}))')
        out.level -= 1

    def wrap_decode(self, out: Lines) -> str:
        doc = '    """Read a DroneCAN payload; ``tao=False`` for CAN FD. Raises DecodeError naming the field."""\n'
        head = f"@classmethod\ndef decode(cls, data: bytes, *, tao: bool = True) -> {self.cls}:\n"
        return head + doc + out.text(1)
