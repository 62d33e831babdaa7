"""Placeholder: filled in by the codec work (issue 3)."""

from __future__ import annotations

from ...ir import Message, Schema
from .extensions import Contribution
from .views import ClassView, ModuleContext


class _Codec:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        return Contribution()

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        return {}


EXTENSION = _Codec()
