"""Encoding and decoding the fixed-size runs of a DroneCAN type (segments, see :mod:`.plan`):
one ``struct`` call per segment, fields not on a byte boundary assembled from shifted pieces."""

from __future__ import annotations

from .....ir import CastMode, CompositeType, Message, PrimitiveKind
from ...literals import py_literal, text_literal, unparenthesized
from ...module_context import ModuleContext
from ...naming import identifier, upper_snake
from .plan import Node, Piece, Planner, Segment, Unit, plan_units
from .values import Lines, decode_pattern, encode_value, error, mask, needs_name

# said where fields off byte boundaries are assembled, since the shifts alone look arbitrary
_SHARED_WORDS = "fields off byte boundaries share words; one over 8 bits has its low byte first (DSDL v0)"


class SegmentEmitter:
    def __init__(self, planner: Planner, msg: Message, cls: str, ctx: ModuleContext, factory: dict[str, str]) -> None:
        self.p = planner
        self.msg = msg
        self.cls = cls
        self.ctx = ctx  # names module-level constants
        self.factory = factory
        self.module_code: list[str] = []  # constants, each after a comment saying what it is
        self.idents = planner.idents(msg)
        self.union_attr = "union_field"

    # -- module-level helpers ---------------------------------------------------------------

    def module_value(self, source: str, role: str, comment: str) -> str:
        """A module-level constant of this class holding ``source``, named for its ``role``
        (``_BATTERY_INFO_ENCODE_STRUCT``); one constant per distinct source."""
        what = ("dronecan", self.cls, role, source)
        new = what not in self.ctx.names
        name = self.ctx.private_name(f"_{upper_snake(self.cls)}_{role}", what)
        if new:
            self.module_code.append(f"# {comment}\n{name} = {source}")
        return name

    def struct_name(self, fmt: str, role: str, comment: str) -> str:
        return self.module_value(f"_struct.Struct({text_literal(fmt)})", role, comment)

    def segment_role(self, seg: Segment, role: str) -> str:
        """``role``, or ``role_FROM_<FIELD>`` for a segment that does not start the message."""
        first = seg.leaves[0].label.split(".", 1)[1] if seg.leaves else ""
        first = first.split(".")[0].split("[")[0]
        starts = self.msg.fields[0] if self.msg.fields else None
        if starts is None or first == ("<void>" if starts.is_padding else starts.name):
            return role
        return f"{role}_FROM_{upper_snake(identifier(first))}"

    def cut_table(self, seg: Segment) -> str:
        rows = [(leaf.offset + leaf.bits, leaf.label) for leaf in seg.leaves]
        comment = "(bit where each field ends, field): names the field a short payload cuts"
        return self.module_value(py_literal(tuple(rows)), self.segment_role(seg, "FIELD_ENDS"), comment)

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
                name = out.named(leaf.label)
                out.add(f"{name} = {raw}")
                raw = name
            value = encode_value(leaf.type, raw, pattern=group)
            if group:
                name = out.named(leaf.label, "bits")
                out.add(f"{name} = {unparenthesized(value)}")
                value = name
            values[idx] = value
        by_unit: dict[int, list[str]] = {}
        if pieces:
            out.add(f"# {_SHARED_WORDS}")
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
        """float16 bits of several fields at once: one runtime call (``_dc.float32_bits``, a struct round trip)
        gives every float32 pattern, from which a positive normal half is a subtraction and a shift; the runtime
        cuts the rest (a sign, a subnormal, beyond +-65504, infinity, NaN: ``_dc.f16bits_saturated`` or, for a
        truncated field, ``_dc.f16bits``), so the common case costs no call per field."""
        halves = [
            (idx, leaf)
            for idx, leaf in enumerate(seg.leaves)
            if leaf.type.kind is PrimitiveKind.FLOAT and leaf.type.bits == 16 and not leaf.nbytes
        ]
        if len(halves) < 2:
            return {}
        truncated = tuple(k for k, (_, leaf) in enumerate(halves) if leaf.type.cast is not CastMode.SATURATED)
        n = len(halves)
        source = f"_dc.float32_bits({n}, truncated={py_literal(truncated)})" if truncated else f"_dc.float32_bits({n})"
        comment = "float16 fields as float32 bits, from which each half is cut"
        bits = self.module_value(source, self.segment_role(seg, "FLOAT32_BITS"), comment)
        # one tuple, read by position (in the order of the call's arguments): each half's cut fits a line
        out.add(f"f32 = {bits}({', '.join(leaf.enc for _, leaf in halves)})")
        values: dict[int, str] = {}
        for k, (idx, leaf) in enumerate(halves):
            g = f"f32[{k}]"
            rest = "_dc.f16bits_saturated" if leaf.type.cast is CastMode.SATURATED else "_dc.f16bits"
            cut = f"(({g} - 0x37FFF000) >> 13) if 0x38800000 <= {g} < 0x477FF000 else {rest}({g})"
            if leaf.structable:  # the struct argument itself
                values[idx] = f"({cut})"
                continue
            h = out.named(leaf.label, "f16")  # shifted into a shared word, where it is used more than once
            out.add(f"{h} = {cut}")
            values[idx] = h
        return values

    def seg_bytes(self, seg: Segment, out: Lines) -> str:
        """Lines packing a segment; returns the expression of its bytes (zero padded)."""
        units, pieces = plan_units(seg)
        args = self.seg_pack_args(seg, units, pieces, out)
        fmt = "<" + "".join(u.pack for u in units)
        comment = "fixed fields as encoded (a float16 as its bit pattern)"
        name = self.struct_name(fmt, self.segment_role(seg, "ENCODE_STRUCT"), comment)
        return f"{name}.pack({', '.join(args) if len(args) > 1 else unparenthesized(args[0])})"

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
                raw = out.named(leaf.label)
                out.add(f"{raw} = {leaf.enc}")
            out.add(f"acc = (acc << {seg.bits}) | {encode_value(leaf.type, raw, pattern=True)}")
            return
        data = self.seg_bytes(seg, out)
        pad = -seg.bits % 8
        shifted = f'(int.from_bytes({data}, "big") >> {pad})' if pad else f'int.from_bytes({data}, "big")'
        out.add(f"acc = (acc << {seg.bits}) | {shifted}")

    # -- segments: decoding ---------------------------------------------------------------

    def seg_unpack(self, seg: Segment, out: Lines, source: str) -> None:
        """Lines unpacking a segment from ``source`` (bytes expression or 'from:<data>'); sets leaf vars."""
        units, pieces = plan_units(seg)
        fmt = "<" + "".join(u.unpack for u in units)
        unit_vars: dict[int, str] = {}
        grouped = {pc.unit for runs in pieces.values() for pc in runs}  # units several fields share
        names = []
        for k, u in enumerate(units):
            if u.pack.endswith("x"):
                continue
            var = out.named(u.leaf.label) if u.leaf is not None and k not in grouped else out.fresh("packed")
            unit_vars[k] = var
            names.append(var)
            if u.leaf is not None:
                u.leaf.var = var
        if names:
            st = self.struct_name(fmt, self.segment_role(seg, "DECODE_STRUCT"), "fixed fields as decoded")
            call = f"{st}.unpack_from({source[5:]})" if source.startswith("from:") else f"{st}.unpack({source})"
            target = ", ".join(names) + ("," if len(names) == 1 else "")
            out.add(f"{target} = {call}")
        if pieces:
            out.add(f"# {_SHARED_WORDS}")
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
            leaf.var = unparenthesized(decode_pattern(leaf.type, bits))  # an argument of the constructor call

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
            var = out.named(live[0].label)
            pattern = decode_pattern(live[0].type, f"((v >> rem) & {mask(seg.bits)})")
            out.add(f"{var} = {unparenthesized(pattern)}")
            live[0].var = var
            return
        nb = (seg.bits + 7) // 8
        pad = -seg.bits % 8
        chunk = f"((v >> rem) & {mask(seg.bits)})"
        if pad:
            chunk = f"({chunk} << {pad})"
        self.seg_unpack(seg, out, f'{chunk}.to_bytes({nb}, "big")')

    def node_expr(self, node: Node) -> str:
        if node.leaf is not None:
            return node.leaf.var
        inner = ", ".join(self.node_expr(n) for n in node.items)
        if node.factory:
            return f"{node.factory}({inner})"
        if node.as_bytes:
            return f"bytes(({inner}{',' if len(node.items) == 1 else ''}))"
        return f"[{inner}]"
