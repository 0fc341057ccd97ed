"""What a dotted key of the case is: its type, dimension and allowed values, and the conversion
of a value written in a sweep file to the value set in the case."""

from __future__ import annotations

import typing
from dataclasses import dataclass
from typing import Any, Literal

from pydantic import BaseModel

from ...config import Case
from ...config.models import _dimension_of
from ...errors import InputError
from ...units import DIMENSIONS, to_si


@dataclass(frozen=True)
class _CaseField:
    key: str
    kind: Literal["float", "int", "bool", "str"]
    dimension: str | None  # key of geardyn.units.DIMENSIONS for quantities
    choices: tuple | None  # allowed values of a Literal field
    description: str

    @property
    def units(self) -> str:
        if self.kind != "float":
            return "1" if self.kind == "int" else ""
        return DIMENSIONS[self.dimension].si_unit if self.dimension else "1"


def _strip_optional(ann: Any) -> Any:
    args = typing.get_args(ann)
    if typing.get_origin(ann) in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        rest = [a for a in args if a is not type(None)]
        return rest[0] if len(rest) == 1 else ann
    return ann


def _case_field(key: str, where: str) -> _CaseField:
    """Resolve a dotted case key to its leaf field, or raise InputError naming ``where``."""
    parts = key.split(".")
    model: type[BaseModel] = Case
    item: type[BaseModel] | None = None  # the model of a list entry (faults.0.depth)
    for i, p in enumerate(parts):
        if item is not None:
            if not p.isdigit() or i == len(parts) - 1:
                raise InputError(where, key, f"an index of the list {'.'.join(parts[:i])} "
                                             "followed by a key, e.g. 'faults.0.depth'")
            model, item = item, None
            continue
        f = model.model_fields.get(p)
        parent = ".".join(parts[:i]) or "the case"
        if f is None or p == "provenance":
            allowed = sorted(n for n in model.model_fields if n != "provenance")
            raise InputError(where, key, f"a dotted key of the case; '{p}' is not a key of "
                                         f"{parent} (allowed: {', '.join(allowed)})")
        ann = _strip_optional(f.annotation)
        if typing.get_origin(ann) is typing.Annotated:
            ann = typing.get_args(ann)[0]
        is_section = isinstance(ann, type) and issubclass(ann, BaseModel)
        entry = typing.get_args(ann)[0] if typing.get_origin(ann) is list else None
        if i < len(parts) - 1 and isinstance(entry, type) and issubclass(entry, BaseModel):
            item = entry  # a list of tables: the next part is an index
            continue
        if i < len(parts) - 1:
            if not is_section:
                raise InputError(where, key, f"a dotted key of the case; "
                                             f"'{'.'.join(parts[:i + 1])}' is a value, not a "
                                             "section")
            model = ann
            continue
        if is_section:
            raise InputError(where, key, "a value of the case, not a whole section (e.g. "
                                         f"'{key}.{next(iter(ann.model_fields))}')")
        desc = f.description or key
        if typing.get_origin(ann) is Literal:
            return _CaseField(key, "str", None, typing.get_args(ann), desc)
        if ann is bool:
            return _CaseField(key, "bool", None, None, desc)
        if ann is int:
            return _CaseField(key, "int", None, None, desc)
        if ann is float:
            return _CaseField(key, "float", _dimension_of(model, p), None, desc)
        if ann is str:
            return _CaseField(key, "str", None, None, desc)
        raise InputError(where, key, "a scalar case value (numbers, whole numbers, booleans or "
                                     "strings can be swept; lists cannot)")
    raise AssertionError("unreachable")  # pragma: no cover


def _convert(fld: _CaseField, value: Any, where: str) -> Any:
    """A value as written -> the value set in the case (SI float, int, bool or str)."""
    if fld.kind == "float":
        return to_si(value, fld.dimension or "dimensionless", where)
    if fld.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(where, value, f"a whole number ({fld.key} is an integer)")
        return int(value)
    if fld.kind == "bool":
        if not isinstance(value, bool):
            raise InputError(where, value, "true or false")
        return value
    if not isinstance(value, str):
        raise InputError(where, value, "a string" + (
            f", one of {', '.join(map(repr, fld.choices))}" if fld.choices else ""))
    if fld.choices and value not in fld.choices:
        raise InputError(where, value, "one of " + ", ".join(map(repr, fld.choices)))
    return value
