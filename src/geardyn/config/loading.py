"""Reading case files: bounded TOML text, ``extends`` chains, ``{ value, source }`` tables,
``--set`` overrides, validation into a :class:`~geardyn.config.models.Case` with provenance
(see :mod:`geardyn.config`)."""

from __future__ import annotations

import copy
import functools
import math
import os
import re
import stat
import tomllib
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from pydantic import (
    BaseModel,
    ValidationError,
)

from ..errors import DataFileError, InputError
from ..units import DIMENSIONS, format_si
from .models import (
    _CONTROL,
    Case,
    _dimension_of,
    _field_dimension,
    _model_field,
    check_text,
)

PAPER_CASE = "xue_howard"


# --------------------------------------------------------------------------- loading
#: Largest case file read [bytes]; a larger file (or a device such as /dev/zero) is refused before
#: it is parsed. The paper's case is about 10 kB; tomllib reads 256 kB of the worst text (a
#: 100,000-element array, 25,000 tables) in well under 2 s.
MAX_CASE_BYTES = 256 * 1024
#: Deepest nesting of arrays/tables in a case file (the paper's case needs 5).
MAX_NESTING = 16
#: Longest chain of ``extends`` (a file extending a file extending ...).
MAX_EXTENDS = 8
#: Longest ``--set`` value [characters].
MAX_OVERRIDE_CHARS = 10_000
#: Keys of a ``{ value = ..., source = ... }`` table (``si`` and ``origin`` are written by
#: ``geardyn config show`` for the reader and ignored on loading).
_META_KEYS = frozenset({"value", "source", "note", "si", "origin"})
#: Source shown by ``config show`` for a value nobody gave (the field's built-in default).
DEFAULT_SOURCE = "geardyn default (built-in value of the field)"
#: Source (and origin) of a command-line override.
SET_SOURCE = "--set"
_UNSOURCED = frozenset({"name", "description"})
_KEY_PART = r'(?:[A-Za-z0-9_-]+|"[^"\n]{0,200}"|\'[^\'\n]{0,200}\')'
# a dotted key of more than MAX_NESTING parts at a line start, after '[' or '{' or ',' (tomllib
# takes quadratic time in the number of parts: 8000 parts take seconds)
_DEEP_KEY = re.compile(r"(?:^|[\[{,])[ \t]*" + _KEY_PART + r"(?:[ \t]*\.[ \t]*" + _KEY_PART
                       + r"){16,}", re.M)
_SCAN = re.compile(r'"""|\'\'\'|["\'#\[\]{}]')
_BASIC_END = re.compile(r'(?:[^"\\\n]|\\.)*"')
_ML_BASIC_END = re.compile(r'(?:[^"\\]|\\.|"(?!""))*"""', re.S)



def _check_strings(node: Any, prefix: str) -> None:
    """:func:`check_text` on every string (keys and values) of raw case data."""
    stack = [(node, prefix)]
    while stack:
        obj, key = stack.pop()
        if isinstance(obj, dict):
            for k, v in obj.items():
                sub = f"{key}.{k}" if key else str(k)
                check_text(k, sub)
                stack.append((v, sub))
        elif isinstance(obj, list):
            stack.extend((v, f"{key}[{i}]") for i, v in enumerate(obj))
        else:
            check_text(obj, key)


def read_case_text(path: str | Path, kind: str = "case file", limit: int = MAX_CASE_BYTES) -> str:
    """Read a case file as UTF-8 text, bounded in size and time.

    Refuses (with :class:`DataFileError` naming the file) a missing file, a directory, anything
    that is not a regular file (``/dev/zero``, a pipe, a socket: they could stream for ever), a
    file larger than ``limit`` bytes (checked before and while reading), and bytes that are not
    UTF-8 (with the offset of the first bad byte).
    """
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise DataFileError(p, "no such file") from None
    except OSError as exc:
        raise DataFileError(p, f"cannot be read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise DataFileError(p, f"is a directory, not a {kind}")
    if not stat.S_ISREG(st.st_mode):
        raise DataFileError(p, f"is not a regular file (a device, pipe or socket), not a {kind}")
    too_big = f"is larger than {limit} bytes, the limit for a {kind}"
    if st.st_size > limit:
        raise DataFileError(p, too_big)
    try:
        with open(p, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise DataFileError(p, f"cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise DataFileError(p, too_big)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataFileError(p, f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                               f"{exc.start}); save it as UTF-8") from None


def _nesting(text: str) -> int:
    """Deepest bracket nesting (``[``/``{``) outside strings and comments of TOML text.

    One linear pass that jumps between brackets, quotes and comments; it stops counting once
    :data:`MAX_NESTING` is passed.
    """
    i, n, depth, deepest = 0, len(text), 0, 0
    while i < n:
        m = _SCAN.search(text, i)
        if m is None:
            break
        t, i = m.group(0), m.end()
        if t == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif t == '"""':
            e = _ML_BASIC_END.match(text, i)
            i = n if e is None else e.end()
        elif t == "'''":
            j = text.find("'''", i)
            i = n if j < 0 else j + 3
        elif t == '"':
            e = _BASIC_END.match(text, i)
            i = (text.find("\n", i) if e is None else e.end())
            i = n if i < 0 else i
        elif t == "'":
            j = text.find("'", i)
            i = n if j < 0 else j + 1
        elif t in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_NESTING:
                break
        else:
            depth = max(0, depth - 1)
    return deepest


def _tree_depth(node: Any) -> int:
    """Depth of nested dicts/lists (iterative: safe for any depth)."""
    deepest, stack = 0, [(node, 1)]
    while stack:
        obj, d = stack.pop()
        if isinstance(obj, dict | list):
            deepest = max(deepest, d)
            if deepest > MAX_NESTING + 8:
                return deepest
            stack.extend((v, d + 1) for v in (obj.values() if isinstance(obj, dict) else obj))
    return deepest


def parse_case_toml(text: str, origin: str) -> dict[str, Any]:
    """Parse case-file text with :mod:`tomllib`, refusing deep nesting and huge numbers first.

    Raises
    ------
    DataFileError
        Naming ``origin``: not valid TOML, nested deeper than :data:`MAX_NESTING`, or a number
        Python refuses to convert (more than 4300 digits).
    """
    if _nesting(text) > MAX_NESTING:
        raise DataFileError(origin, f"nests arrays or tables deeper than {MAX_NESTING} levels")
    if _DEEP_KEY.search(text) is not None:
        raise DataFileError(origin, f"nests keys deeper than {MAX_NESTING} levels (a dotted key "
                                    f"of more than {MAX_NESTING} parts)")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DataFileError(origin, f"is not valid TOML: {exc}") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise DataFileError(origin, f"cannot be read as TOML ({type(exc).__name__}: a number too "
                                    "long or values nested too deeply)") from None
    if _tree_depth(raw) > MAX_NESTING + 8:
        raise DataFileError(origin, f"nests keys deeper than {MAX_NESTING + 8} levels")
    return raw


def _extract_provenance(node: Any, prefix: str, out: dict[str, str]) -> Any:
    """Replace ``{value = v, source = s}`` tables by ``v``, recording ``s`` at the dotted key."""
    if isinstance(node, dict):
        keys = set(node)
        if "value" in keys and keys <= _META_KEYS:
            if "source" in node:
                src = node["source"]
                if not isinstance(src, str):
                    raise InputError(f"{prefix}.source", src, "a text naming where the value "
                                                              "comes from")
                check_text(src, f"{prefix}.source")
                note = node.get("note")
                check_text(note, f"{prefix}.note")
                out[prefix] = src + (f" ({note})" if note is not None else "")
            return node["value"]
        if "value" in keys and "source" in keys:  # a { value, source } table with a typo
            bad = sorted(str(k) for k in keys - _META_KEYS)[0]
            raise InputError(f"{prefix}.{bad}", node[bad], "a known key; unknown key here. "
                             f"Allowed keys in a {{ value, source }} table: "
                             f"{', '.join(sorted(_META_KEYS))}")
        return {k: _extract_provenance(v, f"{prefix}.{k}" if prefix else k, out)
                for k, v in node.items()}
    return node


def _leaves(node: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """``(dotted key, value)`` of every non-table value of plain case data."""
    for k, v in node.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict) and v:
            yield from _leaves(v, key)
        else:
            yield key, v


def _drop_under(mapping: dict[str, str], key: str) -> None:
    for k in [k for k in mapping if k == key or k.startswith(key + ".")]:
        del mapping[k]


def _merge(base: dict[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """``top`` over ``base``: tables merge key by key, anything else replaces."""
    out = dict(base)
    for k, v in top.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def shipped_cases() -> list[str]:
    """Names of the cases shipped with geardyn (usable as ``extends = "<name>"``)."""
    return sorted(f.name[:-5] for f in resources.files("geardyn.cases").iterdir()
                  if f.name.endswith(".toml") and not f.name.startswith("sweep_"))


@dataclass
class _Layers:
    """Raw case data (values as written) merged over its bases, with sources and origins."""

    data: dict[str, Any]
    prov: dict[str, str]
    origin: dict[str, str]


def _shipped_layer(name: str, chain: tuple[str, ...]) -> _Layers:
    """The shipped case ``name`` as a layer (a fresh copy: callers change it).

    The file is read every time and parsed once per text (:func:`_parsed_shipped_layer`):
    parsing the paper's case was 9 of the 10.6 ms of a :func:`paper_case`, paid by every
    command and many thousands of times by the test suite (measured 2026-11-28); the copy
    takes 0.3 ms. An edited file (an editable install) is parsed again. The key is the
    file's own text: a shipped case that extended another shipped file would not see that
    file's edits (none does: ``xue_howard.toml`` is complete).
    """
    label = f"geardyn/cases/{name}.toml"
    text = resources.files("geardyn.cases").joinpath(f"{name}.toml").read_text("utf-8")
    return copy.deepcopy(_parsed_shipped_layer(text, label, chain + (label,), os.getcwd()))


@functools.lru_cache(maxsize=32)
def _parsed_shipped_layer(text: str, label: str, chain: tuple[str, ...], cwd: str) -> _Layers:
    """:func:`_layer_from_text` of a shipped case's ``text``, kept (never hand it out: copy).
    ``cwd`` is part of the key: a base given as a relative file is found from it."""
    return _layer_from_text(text, label, None, chain)


def _file_layer(path: Path, chain: tuple[str, ...]) -> _Layers:
    try:
        ident = str(path.resolve())
    except (OSError, RuntimeError):
        ident = str(path)
    if ident in chain:
        raise InputError("extends", str(path), "a base case that does not extend itself "
                                               "(cycle: " + " -> ".join(chain[-3:]) + ")")
    text = read_case_text(path)
    label = _CONTROL.sub("?", str(path))  # the file's name as a source: printable
    return _layer_from_text(text, label, path, chain + (ident,))


def _layer_from_text(text: str, label: str, path: Path | None, chain: tuple[str, ...]) -> _Layers:
    raw = parse_case_toml(text, label)
    prov: dict[str, str] = {}
    data = _extract_provenance(raw, "", prov)
    explicit = data.pop("provenance", None)
    if explicit is not None:
        if not isinstance(explicit, dict) or not all(isinstance(v, str) for v in explicit.values()):
            raise InputError("provenance", explicit, "a table of dotted key = \"source text\"")
        _check_strings(explicit, "provenance")
        prov = {**explicit, **prov}
    extends = data.pop("extends", PAPER_CASE if path is not None else False)
    complete = extends is False or extends == "none"
    if complete:
        base = _Layers({}, {}, {})
    elif not isinstance(extends, str) or not extends.strip():
        raise InputError("extends", extends, "the name of a shipped case "
                                             f"({', '.join(shipped_cases())}), a case file "
                                             "relative to this one, or false for a complete case")
    else:
        if len(chain) > MAX_EXTENDS:
            raise InputError("extends", extends, f"a chain of at most {MAX_EXTENDS} base cases")
        check_text(extends, "extends")
        if "/" not in extends and not extends.endswith(".toml") and extends in shipped_cases():
            base = _shipped_layer(extends, chain)
        else:
            bp = Path(extends)
            if not bp.is_absolute():
                bp = (path.parent if path is not None else Path.cwd()) / bp
            if not bp.exists():
                raise InputError("extends", extends,
                                 f"a shipped case ({', '.join(shipped_cases())}) or a case file "
                                 f"relative to {label} (no file {bp})")
            base = _file_layer(bp, chain)
        if path is not None:  # the user's case keeps its own name, never its base's
            stem = _CONTROL.sub("?", path.stem)
            data.setdefault("name", stem)
            data.setdefault("description", f"{stem}: changes to {extends}")
    _check_strings(data, "")
    merged = _merge(base.data, data)
    sources, origins = dict(base.prov), dict(base.origin)
    for key, _ in _leaves(data):
        if key in _UNSOURCED:
            continue
        _drop_under(sources, key)
        _drop_under(origins, key)
        if key in prov or not complete:  # a complete file's own values need no file source
            sources[key] = prov.get(key, label)
        origins[key] = label
    for key, src in prov.items():  # sources given in a [provenance] table for inner keys
        sources.setdefault(key, src)
    return _Layers(merged, sources, origins)


def _set_dotted(data: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    if not all(parts):
        raise InputError("--set", key, "a dotted key such as 'pinion.teeth'")
    node = data
    for i, p in enumerate(parts[:-1]):
        if isinstance(node, list):  # an entry of a list of tables: faults.0.depth
            if not p.isdigit() or int(p) >= len(node):
                where = ".".join(parts[:i])
                raise InputError(".".join(parts[: i + 1]), key,
                                 f"an index in [0, {len(node) - 1}] of the list"
                                 if node else
                                 f"an entry of {where}, which is empty in this case: give the "
                                 f"whole list ({where} = [...], or [[{where}]] tables in a "
                                 "case file) before setting one of its fields")
            node = node[int(p)]
            continue
        nxt = node.get(p)
        if nxt is None and (p in ("crack", "modifications", "measurement")
                            or parts[0] == "modifications"):
            nxt = node[p] = {}
        if not isinstance(nxt, dict | list):
            raise InputError(".".join(parts[: i + 1]), nxt if nxt is not None else key,
                             "an existing section of the case (see 'geardyn config show')")
        node = nxt
    if isinstance(node, list):
        raise InputError(key, value, "a key of one entry of the list, e.g. 'faults.0.depth'")
    node[parts[-1]] = value


def parse_overrides(items: Iterable[str] | str) -> dict[str, Any]:
    """Parse ``key=value`` strings; values are TOML values when they parse, else strings.

    ``items`` is an iterable of strings, or one string (a single override: ``"pinion.teeth=25"``
    is ``["pinion.teeth=25"]``, not its characters). Values longer than
    :data:`MAX_OVERRIDE_CHARS` and control characters are refused; anything else than strings
    raises :class:`InputError` naming ``overrides``.

    Examples
    --------
    >>> parse_overrides(["pinion.teeth=25", "simulation.dt=5e-6 s", "crack.enabled=false"])
    {'pinion.teeth': 25, 'simulation.dt': '5e-6 s', 'crack.enabled': False}
    """
    out: dict[str, Any] = {}
    if isinstance(items, str):
        items = [items]
    elif isinstance(items, bytes | bytearray | Mapping) or not isinstance(items, Iterable):
        raise InputError("overrides", items, "'key=value' strings: a list of them or one, e.g. "
                                             "['pinion.teeth=25']")
    for item in items:
        if not isinstance(item, str):
            raise InputError("overrides", item, "'key=value' strings, e.g. 'pinion.teeth=25'")
        if "=" not in item:
            raise InputError("--set", item, "key=value, e.g. 'pinion.teeth=25' or "
                                            "'simulation.dt=\"5e-6 s\"'")
        key, raw = item.split("=", 1)
        key, raw = key.strip(), raw.strip()
        if not key:
            raise InputError("--set", item, "a non-empty dotted key before '='")
        check_text(key, "--set")
        if len(key) > 200:
            raise InputError("--set", key, "a dotted key of at most 200 characters")
        check_text(raw, key)
        if len(raw) > MAX_OVERRIDE_CHARS:
            raise InputError(key, raw, f"a value of at most {MAX_OVERRIDE_CHARS} characters")
        try:
            value = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw
        except (ValueError, RecursionError):
            raise InputError(key, raw, "a number of at most 4300 digits and values nested at "
                                       f"most {MAX_NESTING} deep") from None
        if _tree_depth(value) > MAX_NESTING:
            raise InputError(key, raw, f"a value nested at most {MAX_NESTING} deep")
        _check_strings(value, key)
        out[key] = value
    return out


_OVERRIDES_ALLOWED = ("a 'key=value' string, a list of them (e.g. ['pinion.teeth=25']), or a "
                      "mapping of dotted keys to values (e.g. {'pinion.teeth': 25})")


def _overrides_dict(overrides: Iterable[str] | Mapping[str, Any] | str) -> dict[str, Any]:
    """The overrides of :func:`load_case` / :meth:`Case.with_overrides` as ``{dotted key:
    value}``: a mapping (its keys strings) is copied, strings go through
    :func:`parse_overrides`."""
    if not isinstance(overrides, Mapping):
        if isinstance(overrides, bytes | bytearray) or not isinstance(overrides, Iterable):
            raise InputError("overrides", overrides, _OVERRIDES_ALLOWED)
        return parse_overrides(overrides)
    for key in overrides:
        if not isinstance(key, str):
            raise InputError("overrides", key, "dotted keys (strings) such as 'pinion.teeth'")
    return {k: _plain_value(v) for k, v in overrides.items()}


def _plain_value(value: Any) -> Any:
    """NumPy scalars and arrays as the Python numbers and lists they hold: a loop over
    ``np.arange`` gives ``np.int64`` teeth, which the strict integer fields refused ("got 23;
    allowed: a valid integer", a user audit, 2026-11-27)."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, list | tuple):
        return type(value)(_plain_value(v) for v in value)
    if isinstance(value, dict):
        return {k: _plain_value(v) for k, v in value.items()}
    return value


def _format_validation_error(exc: ValidationError, data: Mapping[str, Any]) -> InputError:
    from .models import FieldProblem

    errs = exc.errors(include_url=False)
    first = errs[0]
    where = tuple(p for p in first["loc"] if not str(p).startswith("function-"))
    msg = first["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    problem = (first.get("ctx") or {}).get("error")
    if isinstance(problem, FieldProblem):  # a section's validator naming one of its fields
        where = (*where, problem.field)
        first = {**first, "loc": where, "input": _raw_value(data, where, None)}
    loc = _dotted(where)
    if first["type"] == "extra_forbidden":
        parent = _dotted(first["loc"][:-1])
        allowed = _allowed_keys(parent)
        msg = f"a known key; unknown key here. Allowed keys{' in ' + parent if parent else ''}: " \
              f"{', '.join(allowed)}"
    elif first["type"] == "missing":
        msg = "a value (this required field is missing)"
    elif first["type"] in _NUMBER_ERRORS and isinstance(first.get("input"), str):
        # "20 dB", "7 %": a plain-number field says what its number is, not pydantic's words
        about = _field_description(where)
        msg = "a plain number, without a unit" + (f" ({about})" if about else "")
    elif msg.startswith("Input should be "):  # "Input should be 'pinion' or 'gear'"
        msg = msg[len("Input should be "):]
    value = _raw_value(data, first["loc"], first.get("input", None))
    more = f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})" if len(errs) > 1 \
        else ""
    return InputError(loc or "case", value, msg + more)


def _dotted(loc: tuple) -> str:
    """A field's name in messages: ``("faults", 0, "front")`` -> ``"faults[0].front"``, as the
    faults' own checks name their entries (:class:`geardyn.faults.base.FaultBase`)."""
    out = ""
    for p in loc:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


#: pydantic error types of a value that is not a number.
_NUMBER_ERRORS = ("float_parsing", "int_parsing", "float_type", "int_type")


def _field_description(loc: tuple) -> str:
    """The description of the case field at ``loc`` (its unit, its meaning), or ''."""
    found = _model_field(loc)
    return (found[0].model_fields[found[1]].description or "").rstrip(".") if found else ""


def _raw_value(data: Mapping[str, Any], loc: tuple, default: Any) -> Any:
    """The value as the user wrote it (before unit conversion), found by its location."""
    node: Any = data
    for p in loc:
        if isinstance(node, Mapping) and p in node:
            node = node[p]
        elif isinstance(node, list) and isinstance(p, int) and p < len(node):
            node = node[p]
        else:
            return default
    return node


def _allowed_keys(parent: str) -> list[str]:
    model: type[BaseModel] = Case
    for p in [q for q in re.split(r"[.\[\]]", parent) if q]:
        if p.isdigit():  # an entry of a list of tables (faults.0): its items' keys
            continue
        f = model.model_fields.get(p)
        if f is None:
            return []
        ann = f.annotation
        sub = [a for a in getattr(ann, "__args__", (ann,)) if isinstance(a, type)
               and issubclass(a, BaseModel)]
        if not sub:
            return []
        model = sub[0]
    keys = sorted(model.model_fields)
    return [k for k in keys if k != "provenance"] + (["extends"] if model is Case else [])


def _model_leaves(model: BaseModel, prefix: str = "") -> Iterator[tuple[str, Any]]:
    for name in type(model).model_fields:
        if name == "provenance":
            continue
        value = getattr(model, name)
        key = f"{prefix}.{name}" if prefix else name
        if isinstance(value, BaseModel):
            yield from _model_leaves(value, key)
        elif isinstance(value, list) and value and isinstance(value[0], BaseModel):
            yield key, [v.model_dump(mode="json", exclude_none=True) for v in value]
        elif name == "faults" and not value:
            continue
        elif value is not None:
            yield key, value


def _validate(data: dict[str, Any], source: str = "", *, faults_checked: bool = True) -> Case:
    """Validate plain case data, naming the first bad field as the user wrote it
    (``faults_checked=False``: the faults' geometry checks left to the caller)."""
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise _format_validation_error(exc, data) from None
    if case.faults and faults_checked:  # the faults' geometry (errors name faults[i].<key>)
        from ..faults import check_faults

        check_faults(case)
    return case


@dataclass(frozen=True)
class CaseDetails:
    """A case with how each of its values was given (for ``geardyn config show``).

    Attributes
    ----------
    case : Case
    written : dict
        Raw case data as written in the files and overrides (unit strings kept), nested.
    origin : dict
        Dotted key -> where the value was given: a case file, ``"--set"``, or ``"default"``.
    """

    case: Case
    written: dict[str, Any]
    origin: dict[str, str]


def load_case_details(path: str | Path | None = None,
                      overrides: Iterable[str] | Mapping[str, Any] = (), *,
                      override_source: str = SET_SOURCE,
                      faults_checked: bool = True) -> CaseDetails:
    """:func:`load_case` keeping the values as written and where each came from
    (``faults_checked=False``: without the faults' geometry checks, for ``geardyn config show``,
    which shows a case it would refuse; :func:`geardyn.faults.check_faults` runs them)."""
    if path is not None and not isinstance(path, str | os.PathLike):
        raise InputError("path", path, "a case file path (str or pathlib.Path), or None for the "
                                       "paper's case")
    ov = _overrides_dict(overrides)
    layers = _shipped_layer(PAPER_CASE, ()) if path is None else _file_layer(Path(path), ())
    data, prov, origin = layers.data, layers.prov, layers.origin
    before = copy.deepcopy(data) if ov else data  # to tell a change from a repeated value
    for key, value in ov.items():
        if isinstance(overrides, Mapping):
            check_text(key, "--set")
            _check_strings(value, key)
        _set_dotted(data, key, value)
        if key in _UNSOURCED:
            continue
        _drop_under(prov, key)
        _drop_under(origin, key)
        prov[key] = override_source
        origin[key] = override_source
    data["provenance"] = prov
    case = _validate(data, faults_checked=False)
    changed = _changed_keys(before, case, [k for k in ov if k not in _UNSOURCED])
    if changed and "name" not in ov:  # no longer the named case: say so
        data["name"] = f"{data.get('name', 'case')} (modified)"
        if "description" not in ov:
            keys = ", ".join(changed[:6]) + (", ..." if len(changed) > 6 else "")
            data["description"] = f"{data.get('description', '')} [changed by {override_source}: " \
                                  f"{keys}]".strip()
        case = _validate(data, faults_checked=False)
    origin = {**{k: "default" for k, _ in _model_leaves(case) if k not in _UNSOURCED}, **origin}
    written = {k: v for k, v in data.items() if k != "provenance"}
    details = CaseDetails(case=case, written=written, origin=origin)
    if case.faults and faults_checked:  # the faults' geometry, the value as the user wrote it
        from ..faults import check_faults

        try:
            check_faults(case)
        except InputError as exc:
            raise with_written_value(exc, details) from None
    return details


_MISSING = object()


def _value_at(case: BaseModel, key: str) -> Any:
    """The validated value at a dotted key (``faults.0.depth`` indexes the list), or _MISSING."""
    node: Any = case
    for p in key.split("."):
        if isinstance(node, BaseModel) and p in type(node).model_fields:
            node = getattr(node, p)
        elif isinstance(node, list) and p.isdigit() and int(p) < len(node):
            node = node[int(p)]
        elif isinstance(node, dict) and p in node:
            node = node[p]
        else:
            return _MISSING
    return node


def _same(a: Any, b: Any) -> bool:
    """Equal validated values (floats to 1e-12 relative: '5 mm' and 0.005 are the same)."""
    if isinstance(a, BaseModel) and isinstance(b, BaseModel):
        a, b = a.model_dump(), b.model_dump()
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        return a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0)
    return type(a) is type(b) and a == b


def _changed_keys(before: dict[str, Any], case: Case, keys: list[str]) -> list[str]:
    """The override ``keys`` whose validated value differs from the case without overrides
    (every key when that case is not valid on its own, e.g. a partial file completed by --set).
    A value set to what the case already has (``--set crack.depth="5 mm"`` on the paper's case)
    is no change."""
    if not keys:
        return []
    try:
        base = _validate(before)
    except InputError:
        return keys
    out = []
    for k in keys:
        old, new = _value_at(base, k), _value_at(case, k)
        if old is _MISSING or new is _MISSING or not _same(old, new):
            out.append(k)
    return out


def with_written_value(exc: InputError, details: CaseDetails) -> InputError:
    """``exc`` with its value as the user wrote it when that was a quantity with a unit, the SI
    value beside (``crack.depth: got '50 mm (= 0.05 m)'``); else ``exc`` itself."""
    if not isinstance(exc.field, str):
        return exc
    key = re.sub(r"\[(\d+)\]", r".\1", exc.field)  # faults[0].width -> faults.0.width
    parts = tuple(int(p) if p.isdigit() else p for p in key.split("."))
    dim = _field_dimension(key)
    faults = details.case.faults
    if (dim is None and len(parts) == 3 and parts[0] == "faults" and isinstance(parts[1], int)
            and parts[1] < len(faults) and parts[2] in type(faults[parts[1]]).model_fields):
        dim = _dimension_of(type(faults[parts[1]]), parts[2])  # the fault type's own field
    written = _raw_value(details.written, parts, None) if dim else None
    if not isinstance(written, str) or isinstance(exc.value, bool) \
            or not isinstance(exc.value, int | float):
        return exc
    si = format_si(exc.value, dim)
    number, _, unit = written.strip().partition(" ")
    try:
        plain = unit.strip() == DIMENSIONS[dim].si_unit and float(number) == exc.value
    except ValueError:
        plain = False
    value = written if plain else f"{written} (= {si})"
    return type(exc)(exc.field, value, exc.allowed)


def load_case(path: str | Path | None = None, overrides: Iterable[str] | Mapping[str, Any] = (),
              *, override_source: str = SET_SOURCE) -> Case:
    """Read and validate a case file, over its base case.

    A case file may give only the values it changes: it extends a base case, the paper's
    (``extends = "xue_howard"``, the default), another shipped case, or another case file
    (``extends = "base.toml"``, relative to the extending file; cycles are refused); ``extends =
    false`` marks a complete case. Tables merge key by key. Values from a base keep their source;
    a value of the file without a ``source`` gets the file's path as its source; overrides get
    ``override_source`` (``"--set"``). A file that extends another keeps its own ``name`` (default:
    the file's stem) and ``description``; overrides rename the case ``"<name> (modified)"`` unless
    they set ``name``.

    Parameters
    ----------
    path : str or Path, optional
        A TOML case file. ``None`` loads the paper's case shipped with geardyn.
    overrides : iterable of str, str or mapping
        ``"dotted.key=value"`` strings (or a mapping) applied before validation; a single
        string is one override (``"pinion.teeth=25"`` means ``["pinion.teeth=25"]``).
    override_source : str
        Source recorded for the overridden values.

    Returns
    -------
    Case

    Raises
    ------
    DataFileError
        If the file is missing, not a regular file, larger than :data:`MAX_CASE_BYTES`, not
        UTF-8, not valid TOML or nested deeper than :data:`MAX_NESTING`.
    InputError
        If a value is invalid; the message names the dotted key, the value and what is allowed.
        Also for a ``path`` that is not a str or path, and ``overrides`` that are not strings or
        a mapping with string keys (field ``"path"`` or ``"overrides"``).
    """
    return load_case_details(path, overrides, override_source=override_source).case


def paper_case(overrides: Iterable[str] | Mapping[str, Any] = ()) -> Case:
    """The paper's case (Xue & Howard 2018, Table 1 plus documented defaults).

    Parameters
    ----------
    overrides : iterable of str, str or mapping, optional
        As in :func:`load_case`: ``"key=value"`` strings (``"motor.torque=80 N m"``), one such
        string, or a mapping of dotted keys to values (numbers in SI units, or strings with a
        unit, ``{"pinion.bearing_stiffness": "2e6 N/m"}``).

    Returns
    -------
    Case
        Validated; every value in SI units, with its source in ``provenance``. With overrides
        the case is renamed ``"xue_howard (modified)"`` and its description names the keys.

    Raises
    ------
    InputError
        A bad key or value (the message names the dotted key, the value and what is allowed).
    """
    return load_case(None, overrides)
