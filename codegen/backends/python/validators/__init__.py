"""The validators extension: ``validate()``, ``check()`` and ``is_known()`` on every generated class.

``validate()`` is straight-line code specialised to the message: one cheap test per field (see
:mod:`.fields` and :mod:`.checks`), then the schema's cross-field rules (``Schema.rules``, from
``schemas/rules/``) compiled by :mod:`.rules`. Violation types and the careful diagnosis live in
the generated runtime module ``_validate.py``.
"""

from __future__ import annotations

from ....ir import Message, Schema
from ....ir.rules import bound_rules
from ..extensions import Contribution
from ..literals import py_literal
from ..module_context import ModuleContext
from ..naming import upper_snake
from ..runtime import copied
from ..views import ClassView
from .describe import check_comment
from .fields import field_code, is_optional
from .rules import known_expr, rule_lines

_INDENT = "    "


def _block(lines: list[str], depth: int) -> list[str]:
    pad = _INDENT * depth
    return [pad + line if line else "" for line in lines]


class _Validators:
    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        return copied("_validate.py")

    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        idents = {fv.source_name: fv.ident for fv in view.fields}
        specs: list[str] = []
        table: list[str] = []
        fast: list[str] = []
        field_names: set[str] = set()
        for f in msg.fields:
            if f.is_padding:
                continue
            ident = idents[f.name]
            spec_name = ctx.constant(view.name, f"{upper_snake(ident)}_SPEC")
            code = field_code(ctx.schema, msg, f, ident, spec_name)
            specs.append(f"{spec_name} = {code.spec_source}")
            table.append(f"({py_literal(f.name)}, {py_literal(ident)}, {spec_name})")
            if code.lines:
                fast += check_comment(ctx.schema, msg, f)
            fast += code.lines
            field_names |= code.names
        checks: list[str] = []
        if fast:
            # one fast test a field; a value of another type than the field's makes a test raise, and
            # then every field is diagnosed the careful way instead (the same findings, in the same order)
            every = ctx.constant(view.name, "FIELD_SPECS")
            specs.append(
                f"# (schema name, attribute, spec) of each field, for the careful way\n{every} = ({', '.join(table)},)"
            )
            checks = [
                "try:",
                *["    " + line for line in fast],
                "except _v.SLOW:  # a field holds a value its fast test cannot take: every field the careful way",
                f"    out = _v.diagnose(self, {every})",
            ]
        if msg.is_union:
            held = ", ".join(f"{py_literal(name)}: self.{ident}" for name, ident in idents.items())
            checks.append(f"_v.union(out, self.union_field, {{{held}}})")
        rule_names: set[str] = set()
        for bound in bound_rules(ctx.schema, msg):
            lines, names = rule_lines(bound, msg, idents)
            checks += lines
            rule_names |= names
        # the locals validate() assigns, declared once: each is reused for fields of different types
        declared = [n for n in ("x", "a", "e", "sub") if n in field_names] + sorted(rule_names)
        body = self._methods(msg, view, checks, declared, idents)
        comment = "# what validate() reports against, field by field (read only when a fast test trips)"
        return Contribution(
            class_body="\n".join(_block(body, 1)) + "\n",
            module_code=("\n".join([comment, *specs]),) if specs else (),
            imports=(f"from {ctx.root()} import _validate as _v",),
        )

    @staticmethod
    def _methods(
        msg: Message, view: ClassView, checks: list[str], local_names: list[str], idents: dict[str, str]
    ) -> list[str]:
        out = [
            "def validate(self) -> list[_v.Violation]:",
            '    """Every violation of the schema and its cross-field rules (empty when valid); warnings included."""',
            "    out: list[_v.Violation] = []",
            *[f"    {name}: _Any" for name in local_names],
            *_block(checks, 1),
            "    return out",
            "",
            "def check(self) -> None:",
            '    """Raise ValidationError, carrying every violation, when validate() finds an error."""',
            "    found = self.validate()",
            "    for v in found:",
            '        if v.severity == "error":',
            f"            raise _v.ValidationError(found, {view.qualified_name})",
            "",
            "def is_known(self, field: str) -> bool:",
            '    """False when the field (schema name) holds its "unknown" sentinel or is absent."""',
        ]
        plain: list[str] = []
        for f in msg.fields:
            if f.is_padding:
                continue
            attr = f"self.{idents[f.name]}"
            test = known_expr(f, attr, is_optional(msg, f))
            if test == "True":
                plain.append(f.name)
                continue
            out += [f"    if field == {_lit(f.name)}:", f"        return {test}"]
        if plain:
            out += [
                "    if field in {" + ", ".join(_lit(n) for n in plain) + "}:",
                "        return True",
            ]
        out.append(f'    raise KeyError(f"{{field!r}} is not a field of " + {view.qualified_name})')
        return out


def _lit(text: str) -> str:
    return py_literal(text)


EXTENSION = _Validators()
