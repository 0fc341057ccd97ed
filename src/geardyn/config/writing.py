"""Writing cases: TOML with a source for every value (``case.toml`` of every output), the
``config show`` view, and the JSON Schema of the case-file format (``config schema``)."""

from __future__ import annotations

import copy
import json
from collections.abc import Mapping
from typing import Any

from pydantic import (
    BaseModel,
)

from ..units import DIMENSIONS, format_si
from .loading import _UNSOURCED, DEFAULT_SOURCE, CaseDetails, _model_leaves, _raw_value, shipped_cases
from .models import Case, _dimension_of, _field_dimension


# --------------------------------------------------------------------------- writing
def _to_toml_tree(model: BaseModel, prov: Mapping[str, str], prefix: str = "") -> dict:
    out: dict[str, Any] = {}
    for name in type(model).model_fields:
        if name == "provenance":
            continue
        value = getattr(model, name)
        key = f"{prefix}.{name}" if prefix else name
        if value is None:
            continue
        if isinstance(value, BaseModel):
            out[name] = _to_toml_tree(value, prov, key)
            continue
        if name == "faults" and not value:
            continue  # no faults: the text of a case without them stays as it was
        if isinstance(value, list) and value and isinstance(value[0], BaseModel):
            value = [_to_toml_tree(v, {}, key) for v in value]  # [[faults]] tables
        dim = _dimension_of(type(model), name)
        if dim is not None and isinstance(value, float):
            value = format_si(value, dim)
        if key in prov and key not in _UNSOURCED:
            value = {"value": value, "source": prov[key]}
        out[name] = value
    return out


def _dumps(tree: Mapping[str, Any]) -> str:
    import tomli_w

    # name, description and extends first, then the sections (tomli-w keeps the order given)
    head = {k: tree[k] for k in ("name", "description", "extends") if k in tree}
    return tomli_w.dumps({**head, **{k: v for k, v in tree.items() if k not in head}})


def case_to_toml(case: Case) -> str:
    """The effective case as TOML text (written by tomli-w), quantities as SI unit strings.

    A value with a recorded source is written as a ``{ value = ..., source = "..." }`` table (a
    ``[section.key]`` table in the text). The text says ``extends = false`` (a complete case) and
    loads back to an equal case with :func:`load_case`.
    """
    tree = _to_toml_tree(case, case.provenance)
    tree["extends"] = False
    return _dumps(tree)


def case_to_display_toml(details: CaseDetails) -> str:
    """The case as ``geardyn config show`` prints it: TOML (loadable by :func:`load_case`) with
    each value as written (``"20 deg"``), its SI value beside when it differs (``si``, stating
    the 2 pi of Hz), its ``source`` and its ``origin`` (base case file, case file, ``"--set"``
    or ``"default"``)."""
    from ..units import hz_note

    case, origin = details.case, details.origin
    tree: dict[str, Any] = {"name": case.name, "description": case.description,
                            "extends": False}
    for key, value in _model_leaves(case):
        if key in _UNSOURCED:
            continue
        written = _raw_value(details.written, tuple(key.split(".")), None)
        dim = _field_dimension(key)
        shown: Any = value
        entry: dict[str, Any] = {}
        if dim is not None and isinstance(value, float):
            si = format_si(value, dim)
            shown = written if isinstance(written, str) else si
            if isinstance(written, str) and written.strip() != si:
                note = hz_note(written) if dim == "angular velocity" else None
                entry["si"] = f"{float(value):.10g} {DIMENSIONS[dim].si_unit}" + \
                    (f" ({note})" if note else "")
        elif key == "faults" and isinstance(value, list):  # [[faults]]: each value as written
            shown = [_as_written(item, written[i] if isinstance(written, list)
                                 and i < len(written) else None) for i, item in enumerate(value)]
        entry = {"value": shown, **entry, "source": case.provenance.get(key, DEFAULT_SOURCE),
                 "origin": origin.get(key, "default")}
        if key == "faults":  # a field of an entry set by --set: the list's origin says so
            # (it named the case file alone for --set faults.0.width, a user audit)
            inner = sorted(k for k in origin if k.startswith("faults."))
            if inner:
                by = "; ".join(f"{k} from {origin[k]}" for k in inner)
                entry["origin"] = f"{entry['origin']}; {by}"
                entry["source"] = f"{entry['source']}; " + "; ".join(
                    f"{k}: {case.provenance.get(k, origin[k])}" for k in inner)
        node = tree
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = entry
    return _dumps(tree)


def _as_written(item: dict[str, Any], written: Any) -> dict[str, Any]:
    """A ``[[faults]]`` entry (SI values) with each quantity as the case file or ``--set``
    wrote it (``"3 deg"``, not ``0.05235987755982989``); it validated to the SI value, so the
    entry loads back to the same fault."""
    if not isinstance(written, dict):
        return item
    return {k: written[k] if isinstance(written.get(k), str) and not isinstance(v, str) else v
            for k, v in item.items()}


#: Keys of a ``{ value = ..., source = ... }`` table, as the JSON schema describes them.
_SOURCE_TABLE_KEYS = {
    "source": {"type": "string", "description": "Where the value comes from (kept as its "
                                                "provenance)."},
    "note": {"description": "Appended to the source in parentheses."},
    "si": {"description": "Written by 'geardyn config show' (the SI value); ignored on loading."},
    "origin": {"description": "Written by 'geardyn config show' (where the value was given); "
                              "ignored on loading."},
}
#: Models whose tables sit in a list (``[[faults]]``): a list replaces its base's whole, so
#: their required keys stay required, and their values cannot be ``{ value, source }`` tables
#: (only tables are searched for them, not lists).
_LIST_ITEM_MODELS = frozenset({"FaultConfig"})


def _sourced(schema: dict[str, Any]) -> dict[str, Any]:
    """``schema``, or the same value written as a ``{ value = ..., source = ... }`` table."""
    meta = {k: schema[k] for k in ("title", "description", "default") if k in schema}
    table = {"type": "object", "properties": {"value": schema, **_SOURCE_TABLE_KEYS},
             "required": ["value"], "additionalProperties": False}
    return {**meta, "anyOf": [schema, table]}


def _def_refs(schema: Any) -> list[str]:
    """Names of the ``$defs`` a property refers to directly or through ``anyOf`` (not through
    ``items``: list entries are not merged with a base)."""
    if not isinstance(schema, dict):
        return []
    ref = schema.get("$ref", "")
    out = [ref.rsplit("/", 1)[1]] if ref.startswith("#/$defs/") else []
    for sub in schema.get("anyOf", ()):
        out += _def_refs(sub)
    return out


def case_file_schema() -> dict[str, Any]:
    """JSON schema (draft 2020-12) of case *files*, as :func:`load_case` reads them.

    From the pydantic model's schema (:class:`Case`), with what the file format adds:

    * ``extends``: a shipped case, a case file, or ``false`` / ``"none"`` for a complete case;
    * every value (and table) of a section may be a ``{ value = ..., source = "..." }`` table
      (keys ``value``, ``source``, ``note``, ``si``, ``origin``), as the shipped case writes them
      and ``geardyn config show`` prints them; not inside the ``[[faults]]`` list;
    * no key is required in a file that extends a base (a partial case: any key may come from
      the base); a complete file (``extends = false`` or ``"none"``) must hold the sections and
      keys the model requires; a ``[[faults]]`` entry is always complete (lists replace);
    * quantities are a number in SI units or a string with a unit (``"5 mm"``), as the model's
      schema says (``x-unit``, ``x-dimension``); the ``[provenance]`` table of dotted key =
      source.

    Not described: the checks of values against each other (model validators, e.g. the load
    law's fields, ``centre_distance_max >= centre_distance_min``), the units a quantity string
    may use, and pydantic's lax conversions (a number written as a string for a plain number).
    """
    model = Case.model_json_schema()
    defs: dict[str, Any] = model.pop("$defs", {})
    complete: dict[str, Any] = {}

    def loosen(name: str, schema: dict[str, Any]) -> dict[str, Any]:
        out = copy.deepcopy(schema)
        if name in _LIST_ITEM_MODELS:
            return out
        required = out.pop("required", [])
        props = out.get("properties", {})
        skeleton: dict[str, Any] = {}
        for key, sub in props.items():
            refs = [r for r in _def_refs(sub) if r not in _LIST_ITEM_MODELS]
            if refs:  # a section: in a complete file its own required keys apply
                skeleton[key] = {"anyOf": [{"$ref": f"#/$defs/{refs[0]}.complete"},
                                           {"not": {"$ref": f"#/$defs/{refs[0]}"}}]}
            if key != "provenance":
                props[key] = _sourced(sub)
        complete[f"{name}.complete"] = {"required": required, "properties": skeleton} \
            if required else {"properties": skeleton}
        return out

    file_defs = {name: loosen(name, d) for name, d in defs.items()}
    root = loosen("Case", model)
    root["properties"]["extends"] = _sourced({
        "description": "The base case this file changes: a shipped case "
                       f"({', '.join(shipped_cases())}) or a case file relative to this one "
                       "(default: xue_howard); false or \"none\" for a complete case.",
        "anyOf": [{"const": False}, {"type": "string", "pattern": "\\S"}],
    })
    root["allOf"] = [{
        "if": {"properties": {"extends": {"enum": [False, "none"]}}, "required": ["extends"]},
        "then": {"$ref": "#/$defs/Case.complete"},
    }]
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **root,
            "$defs": {**file_defs, **complete}}


def case_schema() -> str:
    """JSON schema of case files (pretty-printed JSON text, :func:`case_file_schema`)."""
    return json.dumps(case_file_schema(), indent=2)


def deep_copy_case_data(case: Case) -> dict[str, Any]:
    """Plain-Python copy of a case's values (SI floats), for hashing and serialisation."""
    exclude = {"provenance"} | (set() if case.faults else {"faults"})  # as before faults
    return copy.deepcopy(case.model_dump(mode="json", exclude=exclude))
