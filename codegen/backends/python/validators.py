"""Placeholder: filled in by the validators work (issue 4)."""

from __future__ import annotations

from ...ir import Message, Schema
from .extensions import Contribution
from .views import ClassView, ModuleContext


class _Validators:
    def contribute(self, msg: Message, ctx: ModuleContext, view: ClassView) -> Contribution:
        return Contribution()

    def runtime_files(self, schema: Schema, header: str) -> dict[str, str]:
        return {}


EXTENSION = _Validators()
