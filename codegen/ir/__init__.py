"""The intermediate representation (IR): frontends produce it, backends consume it.

The model is split by concern (``basics``, ``fieldtypes``, ``fields``, ``messages``, ``mappings`` with
``ops``, ``schema`` with ``expr``); this package face re-exports it so that users write
``from codegen.ir import Message``. ``json_form`` is the IR as JSON (``battgen ir``), ``units`` the one unit registry.
"""

from .basics import (
    Location,
    SchemaWarning,
    SourceFormat,
    Unit,
)
from .fields import (
    Constant,
    EnumDef,
    EnumEntry,
    EnumKind,
    Field,
    Sentinel,
)
from .fieldtypes import (
    FLOAT_MAX,
    ArrayType,
    CastMode,
    Column,
    CompositeType,
    FieldType,
    PrimitiveKind,
    PrimitiveType,
    Range,
    StringType,
    allowed_range,
    type_bounds,
)
from .mappings import (
    CONCEPTS_ENDPOINT,
    Concept,
    Direction,
    Endpoint,
    FieldRef,
    Mapping,
    MappingSet,
    Rule,
)
from .messages import (
    CyphalInfo,
    CyphalKind,
    DevicetreeInfo,
    DronecanInfo,
    DronecanKind,
    MavlinkInfo,
    Message,
    PdefInfo,
    StructSlot,
    UorbInfo,
)
from .ops import MappingOp
from .schema import (
    CrossFieldRule,
    Schema,
)

__all__ = [
    "CONCEPTS_ENDPOINT",
    "FLOAT_MAX",
    "ArrayType",
    "CastMode",
    "Column",
    "CompositeType",
    "Concept",
    "Constant",
    "CrossFieldRule",
    "CyphalInfo",
    "CyphalKind",
    "DevicetreeInfo",
    "Direction",
    "DronecanInfo",
    "DronecanKind",
    "Endpoint",
    "EnumDef",
    "EnumEntry",
    "EnumKind",
    "Field",
    "FieldRef",
    "FieldType",
    "Location",
    "Mapping",
    "MappingOp",
    "MappingSet",
    "MavlinkInfo",
    "Message",
    "PdefInfo",
    "PrimitiveKind",
    "PrimitiveType",
    "Range",
    "Rule",
    "Schema",
    "SchemaWarning",
    "Sentinel",
    "SourceFormat",
    "StringType",
    "StructSlot",
    "Unit",
    "UorbInfo",
    "allowed_range",
    "type_bounds",
]
