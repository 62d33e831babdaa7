"""The grammar of devicetree source (.dts/.dtsi, dtc's /dts-v1/ language) into a tree.Node.

Integer expressions are evaluated here with dtc's semantics: unsigned 64-bit arithmetic, then
the value must fit the cell width (a negative number fits as its two's complement).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from .scan import CPP_HINT, Scanner
from .tree import Draft, Node, Prop, Ref, attach, delete, find, merge

_NAME = re.compile(r"[A-Za-z0-9,._+*#?@-]+")
_LABEL = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_LABEL_DEF = re.compile(r"([A-Za-z_][A-Za-z0-9_]*):")
_REF = re.compile(r"&(?:\{([A-Za-z0-9,._+*#?@/-]*)\}|([A-Za-z_][A-Za-z0-9_]*))")
_LITERAL = re.compile(r"(0[xX][0-9a-fA-F]+|[0-9]+)(?:ULL|LL|UL|U|L)?(?![A-Za-z0-9_])", re.IGNORECASE)
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_HEXBYTE = re.compile(r"[0-9a-fA-F]{2}")
_MASK64 = (1 << 64) - 1
MAX_INCBIN = 16 << 20  # bytes one /incbin/ may bring in (a board's firmware blob is far smaller)


def _clip(name: str) -> str:
    return name if len(name) <= 60 else name[:57] + "..."


def _quoted(name: str) -> str:
    """A node or property name in a message, cut to a line (hostile input can make one megabytes long)."""
    return repr(name) if len(name) <= 60 else repr(name[:57]) + "..."


_MAX_DIGITS = 256  # digits of one literal (a 64-bit cell needs 20 in decimal, 16 in hex)


class Parser:
    def __init__(self, path: Path, display: str, root: Path | None = None) -> None:
        self.s = Scanner(path, display, root)
        self.root: Node | None = None

    # -- file level -------------------------------------------------------------------------

    def parse(self, require_header: bool) -> Node:
        s = self.s
        seen_header = False
        while s.take("/dts-v1/"):
            s.expect(";", "';' after /dts-v1/")
            seen_header = True
            if s.at("/plugin/"):
                raise s.error("/plugin/ overlays are not supported: expected a complete devicetree")
        if require_header and not seen_header:
            raise s.error(f"expected /dts-v1/; at the start of the file, found {s.describe()}")
        while s.take("/memreserve/"):
            self._prim()
            self._prim()
            s.expect(";", "';' after /memreserve/ <address> <size>")
        while not s.eof():
            self._top_statement()
        if self.root is None:
            raise s.error("expected a root node '/ { ... };'")
        return self.root

    def _top_statement(self) -> None:
        s = self.s
        at = s.where()
        if s.take("/delete-node/"):
            delete(self._node_ref())
            s.expect(";", "';' after /delete-node/ &label")
            return
        if s.take("/omit-if-no-ref/"):
            self._node_ref().omit_if_no_ref = True
            s.expect(";", "';' after /omit-if-no-ref/ &label")
            return
        labels = self._labels()
        if s.at("&"):
            target = self._node_ref()
            block = self._body("", labels, at)
            merge(target, block)
            return
        if s.take("/"):
            block = self._body("", labels, at)
            if self.root is None:
                self.root = block
            else:
                merge(self.root, block)
            return
        if s.at("#"):
            raise s.error(f"unexpected {s.describe()}: if this is C preprocessor input, {CPP_HINT}")
        raise s.error(f"expected '/ {{', '&label {{', /delete-node/ or /memreserve/, found {s.describe()}")

    def _node_ref(self) -> Node:
        s = self.s
        ref = self._ref()
        if ref is None:
            raise s.error(f"expected a node reference &label or &{{/path}}, found {s.describe()}")
        if self.root is None:
            raise s.error(f"reference &{ref.text} before the root node '/ {{ ... }};'")
        node = find(self.root, ref)
        if node is None:
            raise s.error(
                f"reference &{ref.text} names no node: expected a label or path defined above", (ref.file, ref.line)
            )
        return node

    def _ref(self) -> Ref | None:
        s = self.s
        s.ws()
        file, line = s.where()
        m = _REF.match(s.src.text, s.src.pos)
        if not m:
            return None
        s.src.pos = m.end()
        return Ref(m.group(1) if m.group(1) is not None else m.group(2), file, line)

    def _labels(self) -> list[str]:
        s = self.s
        labels: list[str] = []
        while True:
            s.ws()
            m = _LABEL_DEF.match(s.src.text, s.src.pos)
            if not m:
                return labels
            s.src.pos = m.end()
            labels.append(m.group(1))

    # -- nodes --------------------------------------------------------------------------------

    def _body(self, name: str, labels: list[str], at: tuple[str, int]) -> Node:
        s = self.s
        s.expect("{", f"'{{' to open node {_clip(name) if name else '/'}")
        node = Node(name, at[0], at[1], labels=list(labels))
        seen_child = False
        while not s.take("}"):
            if s.eof():
                raise s.error(f"expected '}}' to close node {_clip(name) if name else '/'} opened at {at[0]}:{at[1]}")
            stmt_at = s.where()
            if s.take("/delete-property/"):
                pname = self._name("a property name after /delete-property/")
                s.expect(";", f"';' after /delete-property/ {pname}")
                if seen_child:
                    raise s.error("properties must come before child nodes", stmt_at)
                node.props.append(self._prop(pname, [], stmt_at, deleted=True))
                continue
            if s.take("/delete-node/"):
                cname = self._name("a node name after /delete-node/")
                s.expect(";", f"';' after /delete-node/ {cname}")
                marker = Node(cname, stmt_at[0], stmt_at[1], deleted=True)
                attach(node, marker)
                seen_child = True
                continue
            omit = s.take("/omit-if-no-ref/")
            labels_here = self._labels()
            stmt_at = s.where()
            item = self._name("a property or child node name")
            if s.at("{"):
                child = self._body(item, labels_here, stmt_at)
                child.omit_if_no_ref = omit
                attach(node, child)
                seen_child = True
                continue
            if omit:
                raise s.error("/omit-if-no-ref/ applies to nodes: expected '{'")
            if seen_child:
                raise s.error(f"property {_quoted(item)} after a child node: properties must come first", stmt_at)
            value = self._value() if s.take("=") else []
            s.expect(";", f"';' after property {_quoted(item)}")
            node.props.append(self._prop(item, value, stmt_at))
        s.expect(";", f"';' after the closing '}}' of node {_clip(name) if name else '/'}")
        return node

    def _prop(self, name: str, value: list[Draft], at: tuple[str, int], deleted: bool = False) -> Prop:
        return Prop(name, value, at[0], at[1], deleted=deleted)

    def _name(self, what: str) -> str:
        s = self.s
        s.ws()
        name = s.match(_NAME)
        if name is None:
            raise s.error(f"expected {what}, found {s.describe()}")
        return name

    # -- values -------------------------------------------------------------------------------

    def _value(self) -> list[Draft]:
        s = self.s
        parts: list[Draft] = []
        while True:
            self._labels()
            parts.append(self._piece())
            self._labels()
            if not s.take(","):
                return parts

    def _piece(self) -> Draft:
        s = self.s
        s.ws()
        if s.peek('"'):
            return Draft("string", s.read_string())
        if s.take("/bits/"):
            s.ws()
            at = s.where()
            lit = s.match(_LITERAL)
            if lit is None:
                raise s.error(f"expected a width 8, 16, 32 or 64 after /bits/, found {s.describe()}")
            bits = self._literal(lit, at)
            if bits not in (8, 16, 32, 64):
                raise s.error(f"/bits/ {lit}: expected 8, 16, 32 or 64", at)
            return self._cells(bits)
        if s.peek("<"):
            return self._cells(32)
        if s.take("["):
            return self._bytestring()
        if s.take("/incbin/"):
            return self._incbin()
        ref = self._ref()
        if ref is not None:
            return Draft("path", ref)
        self._macro_check("a property value")
        raise s.error(f'expected a value ("string", <cells>, [bytes] or &label), found {s.describe()}')

    def _macro_check(self, where: str) -> None:
        s = self.s
        m = _IDENT.match(s.src.text, s.src.pos)
        if m:
            raise s.error(f"{m.group(0)!r} in {where} looks like a C preprocessor macro: {CPP_HINT}")

    def _cells(self, bits: int) -> Draft:
        s = self.s
        s.expect("<", "'<' to open cells")
        items: list[int | Ref] = []
        while not s.take(">"):
            self._labels()
            if s.take(">"):
                break
            at = s.where()
            ref = self._ref()
            if ref is not None:
                if bits != 32:
                    raise s.error(f"&{ref.text}: references are only allowed in 32-bit cells, not /bits/ {bits}", at)
                items.append(ref)
                continue
            if s.eof():
                raise s.error("expected '>' to close cells, found end of file")
            value = self._prim()
            if bits < 64:
                mask = (1 << bits) - 1
                if value > mask and (value | mask) != _MASK64:
                    raise s.error(f"value {value:#x} does not fit a {bits}-bit cell", at)
                value &= mask
            items.append(value)
        return Draft("cells", items, bits)

    def _bytestring(self) -> Draft:
        s = self.s
        out = bytearray()
        while not s.take("]"):
            self._labels()
            s.ws()
            if s.take("]"):
                break
            pair = s.match(_HEXBYTE)
            if pair is None:
                raise s.error(f"expected hex byte pairs such as 0a or ']' in a byte string, found {s.describe()}")
            out.append(int(pair, 16))
        return Draft("bytes", bytes(out))

    def _incbin(self) -> Draft:
        s = self.s
        at = s.where()
        s.expect("(", "'(' after /incbin/")
        s.ws()
        if not s.peek('"'):
            raise s.error("expected a quoted file name in /incbin/(...)")
        name = s.read_string()
        offset, length = 0, -1
        if s.take(","):
            offset = self._expr()
            s.expect(",", "', length' after the /incbin/ offset")
            length = self._expr()
        s.expect(")", "')' to close /incbin/(...)")
        base = s.src.path.parent if s.src.path else Path.cwd()
        target = (base / name).resolve()
        if not s.allowed(target):
            raise s.error(f'/incbin/ "{name}": outside the folder of {s.stack[0].display} ({s.allowed_text()})', at)
        try:
            if not target.is_file():  # /dev/zero, a FIFO: no end, or none to trust
                raise s.error(f'/incbin/ "{name}": not a regular file', at)
            size = target.stat().st_size
            end = size if length < 0 else offset + length
            if end > size:
                raise s.error(f'/incbin/ "{name}": asks for bytes {offset}..{end} of a {size}-byte file', at)
            if end - offset > MAX_INCBIN:
                raise s.error(
                    f'/incbin/ "{name}": {end - offset} bytes, more than the {MAX_INCBIN} a property may hold', at
                )
            with target.open("rb") as fh:  # only the slice asked for
                fh.seek(offset)
                data = fh.read(end - offset)
        except OSError as exc:
            raise s.error(f'/incbin/ "{name}": cannot read ({exc.strerror or exc})', at) from None
        return Draft("bytes", data)

    # -- integer expressions (dtc: unsigned 64-bit, C precedence) ---------------------------

    def _prim(self) -> int:
        s = self.s
        s.ws()
        at = s.where()
        if s.peek("("):
            s.take("(")
            value = self._expr()
            s.expect(")", "')' to close the expression")
            return value
        if s.peek("'"):
            return s.read_char_literal()
        lit = s.match(_LITERAL)
        if lit is not None:
            value = self._literal(lit, at)
            if value > _MASK64:
                raise s.error(f"integer literal {lit} does not fit 64 bits", at)
            return value
        if s.peek("-"):
            raise s.error("negative numbers need parentheses in cells: expected (-N)")
        self._macro_check("cells")
        raise s.error(f"expected a number, 'c' or (expression), found {s.describe()}")

    def _literal(self, text: str, at: tuple[str, int]) -> int:
        digits = re.match(r"0[xX][0-9a-fA-F]+|[0-9]+", text)
        assert digits is not None
        d = digits.group(0)
        if len(d) > _MAX_DIGITS:  # a cell holds 64 bits; Python refuses to convert 4,300 decimal digits
            raise self.s.error(f"a number of {len(d)} digits: expected at most {_MAX_DIGITS}", at)
        if d[:2].lower() == "0x":
            return int(d[2:], 16)
        if len(d) > 1 and d[0] == "0":
            if not re.fullmatch(r"[0-7]+", d):
                raise self.s.error(f"{text} is not an octal number (a leading 0 means octal)", at)
            return int(d, 8)
        return int(d)

    def _expr(self) -> int:
        cond = self._binary(0)
        if self.s.take("?"):
            yes = self._expr()
            self.s.expect(":", "':' in a ?: expression")
            no = self._expr()
            return yes if cond else no
        return cond

    def _binary(self, level: int) -> int:
        if level == len(_LEVELS):
            return self._unary()
        left = self._binary(level + 1)
        while True:
            op = self._operator(_LEVELS[level])
            if op is None:
                return left
            at = self.s.where()
            right = self._binary(level + 1)
            if op in ("/", "%") and right == 0:
                raise self.s.error("division by zero in an expression", at)
            left = _OPS[op](left, right) & _MASK64

    def _operator(self, ops: tuple[str, ...]) -> str | None:
        s = self.s
        s.ws()
        for op in ops:
            if s.peek(op) and not any(s.peek(longer) for longer in _LONGER.get(op, ())):
                s.src.pos += len(op)
                return op
        return None

    def _unary(self) -> int:
        s = self.s
        if s.take("-"):
            return -self._unary() & _MASK64
        if s.take("~"):
            return ~self._unary() & _MASK64
        if s.at("!") and not s.peek("!="):
            s.take("!")
            return int(self._unary() == 0)
        return self._prim()


_LEVELS: tuple[tuple[str, ...], ...] = (
    ("||",),
    ("&&",),
    ("|",),
    ("^",),
    ("&",),
    ("==", "!="),
    ("<=", ">=", "<", ">"),
    ("<<", ">>"),
    ("+", "-"),
    ("*", "/", "%"),
)
# An operator is not taken when the text continues into a longer one (| of ||, < of << or <=).
_LONGER = {"|": ("||",), "&": ("&&",), "<": ("<<", "<="), ">": (">>", ">=")}
_OPS: dict[str, Callable[[int, int], int]] = {
    "||": lambda a, b: int(bool(a) or bool(b)),
    "&&": lambda a, b: int(bool(a) and bool(b)),
    "|": lambda a, b: a | b,
    "^": lambda a, b: a ^ b,
    "&": lambda a, b: a & b,
    "==": lambda a, b: int(a == b),
    "!=": lambda a, b: int(a != b),
    "<=": lambda a, b: int(a <= b),
    ">=": lambda a, b: int(a >= b),
    "<": lambda a, b: int(a < b),
    ">": lambda a, b: int(a > b),
    "<<": lambda a, b: a << b if b < 64 else 0,
    ">>": lambda a, b: a >> b if b < 64 else 0,
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a // b,
    "%": lambda a, b: a % b,
}
