"""Generated code survives any identifier a schema can hold (issue 10, item 5).

The generated modules import what they use under private aliases, and a member whose name would clash
with a name the generated code needs is renamed by the one rule in ``naming`` (a trailing ``_``). The
package generated from tests/samples.py's clashing schema is also type-checked by tests/test_typing.py.
"""

from __future__ import annotations

import ast
import builtins
import keyword
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

from conftest import ROOT
from samples import clashing_schema

from codegen.backends.python import naming
from codegen.backends.python.writer import generate
from codegen.frontends import uorb
from codegen.ir import Schema

Importer = Callable[..., ModuleType]


def test_a_type_named_classvar_leaves_later_constants_class_variables(import_generated: Importer) -> None:
    uorb = import_generated(clashing_schema(), "uorb")
    # the reproducer: a class named ClassVar made later classes' constants into fields
    struct_cls: Any = uorb.Struct
    assert struct_cls.from_dict(struct_cls().to_dict()).QUALIFIED_NAME == "uorb.Struct"
    assert struct_cls.K == 7 and "K" not in {f.name for f in _fields(struct_cls)}
    assert uorb.ClassVar.QUALIFIED_NAME == "uorb.ClassVar"
    assert uorb.Any.QUALIFIED_NAME == "uorb.Any" and uorb.Mapping.QUALIFIED_NAME == "uorb.Mapping"
    # a class spelled like a builtin the module's code raises takes the trailing "_"
    assert uorb.ValueError_.QUALIFIED_NAME == "uorb.ValueError"


def test_members_named_like_modules_and_builtins_round_trip(import_generated: Importer) -> None:
    cls: Any = import_generated(clashing_schema(), "uorb").ClassVar
    names = [f.name for f in _fields(cls)]
    # modules are private aliases in generated code: these names stay as the schema spells them
    assert {"dataclasses", "struct", "math", "enum"} <= set(names)
    # builtins the class body names get the trailing "_"; so do members the class itself defines and the
    # names of the module's classes (the class body names them in annotations)
    assert {"int_", "float_", "str_", "bool_", "Any_"} <= set(names)
    assert cls.dataclasses_ == 1 and cls.QUALIFIED_NAME_ == 2 and cls.ClassVar_ == 3
    obj = cls(dataclasses=4, int_=5, Any_=6)
    assert cls.from_dict(obj.to_dict()) == obj
    assert obj.to_dict()["int"] == 5  # the data keeps the schema's names


def test_enum_entries_named_like_enum_attributes(import_generated: Importer) -> None:
    kind: Any = import_generated(clashing_schema(), "uorb").ClassVarKind
    assert [m.name for m in kind] == ["mro_", "name_", "value_", "real_", "to_bytes_"]
    assert kind.mro_ == 0 and kind(4).to_bytes(1, "little") == b"\x04"


def test_a_member_named_like_a_class_of_its_module(import_generated: Importer) -> None:
    ns: Any = import_generated(clashing_schema(), "dronecan.ns")
    outer = ns.Outer(Inner_=ns.Inner(Outer_=3), Outer_=1.5)
    assert ns.Outer.decode(outer.encode()) == outer
    assert outer.to_dict() == {"Inner": {"Outer": 3}, "Outer": 1.5, "float": 0.0}


def test_the_class_scope_names_cover_what_class_bodies_use(tmp_path: Path) -> None:
    """naming.CLASS_SCOPE_NAMES must hold every builtin a generated class body names unqualified, and
    no other name a class body uses may be one a schema can spell."""
    generate(clashing_schema(), tmp_path / "clashing")
    for package in (ROOT / "generated", tmp_path / "clashing"):
        rendered = [p for p in package.rglob("*.py") if not p.name.startswith("_") or p.name == "__init__.py"]
        for path in sorted(rendered):  # the runtime modules (_meta.py, ...) hold no schema names
            for name in _class_scope_names(ast.parse(path.read_text(encoding="utf-8"))):
                if name in dir(builtins):
                    assert name in naming.CLASS_SCOPE_NAMES, f"{path}: class body uses builtin {name!r}"
                else:
                    spelled = naming.identifier(name) == name or naming.class_identifier(name) == name
                    assert name.startswith("_") or not spelled or name[0].isupper(), f"{path}: {name!r}"


def test_identifier_rule_on_names_python_reserves() -> None:
    for word in [*keyword.kwlist, *(w for w in keyword.softkwlist if w != "_")]:
        assert naming.identifier(word) == word + "_"
    assert naming.identifier("decode") == "decode_" and naming.identifier("int") == "int_"
    assert naming.identifier("type") == "type"  # not used by class bodies: MAVLink's BATTERY_STATUS.type stays
    assert naming.identifier("__init__") == "init" and naming.identifier("2nd") == "_2nd"
    assert naming.class_identifier("Exception") == "Exception_"
    assert naming.enum_member("CELLS_2S", "CELLS") == "CELLS_2S"


def test_generate_from_clashing_uorb_files_compiles(tmp_path: Path, import_generated: Importer) -> None:
    """The same through the uORB frontend and the CLI: every module written compiles and imports."""
    src = tmp_path / "msg"
    src.mkdir()
    (src / "ClassVar.msg").write_text(
        "uint64 timestamp\nuint8 dataclasses\nuint8 struct\nfloat32 int\nuint8 kind # [@enum KIND]\n"
        "uint8 KIND_mro = 0\nuint8 KIND_name = 1\nuint8 QUALIFIED_NAME = 3\n",
        encoding="utf-8",
    )
    (src / "Mapping.msg").write_text("uint64 timestamp\nClassVar inner\nfloat32 bool\n", encoding="utf-8")
    schema: Schema = uorb.parse_dir(src)
    package: Any = import_generated(schema, "uorb", package="clashpkg")
    for path in sorted((tmp_path / "clashpkg").rglob("*.py")):
        compile(path.read_text(encoding="utf-8"), str(path), "exec")
    obj = package.Mapping(inner=package.ClassVar(dataclasses=1, struct=2, int_=0.5, kind=1), bool_=2.5)
    assert package.Mapping.decode(obj.encode()) == obj
    assert package.ClassVar.QUALIFIED_NAME_ == 3 and package.ClassVarKind.name_ == 1


def _fields(cls: type) -> Iterator[Any]:
    import dataclasses

    return iter(dataclasses.fields(cls))


def _class_scope_names(tree: ast.Module) -> set[str]:
    """Names evaluated in a class body: annotations, defaults, decorators, method signatures."""
    out: set[str] = set()
    for node in tree.body:
        if not isinstance(node, ast.ClassDef):
            continue
        for item in node.body:
            exprs: list[ast.expr | None] = []
            if isinstance(item, ast.AnnAssign):
                exprs += [item.annotation, item.value]
            elif isinstance(item, ast.Assign):
                exprs.append(item.value)
            elif isinstance(item, ast.FunctionDef):
                a = item.args
                exprs += [x.annotation for x in [*a.posonlyargs, *a.args, *a.kwonlyargs]]
                exprs += [item.returns, *item.decorator_list, *a.defaults, *a.kw_defaults]
            for expr in exprs:
                for sub in ast.walk(expr) if expr is not None else ():
                    if isinstance(sub, ast.Name):
                        out.add(sub.id)
    return out
