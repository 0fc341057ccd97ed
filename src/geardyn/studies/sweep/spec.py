"""The sweep file: validation, the base case, and the expansion into runs.

See :mod:`geardyn.studies.sweep` for the format. Quantities take unit strings and are converted
with the unit handling of :mod:`geardyn.config` (:func:`geardyn.units.to_si` with the dimension
of the case field a dotted key names); every value is checked by building the case with
:meth:`geardyn.config.Case.with_overrides`.
"""

from __future__ import annotations

import math
import os
import tomllib
import typing
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ...config import Case, _dimension_of, deep_copy_case_data, load_case
from ...errors import DataFileError, InputError
from ...units import DIMENSIONS, to_si

__all__ = ["SweepFile", "RangeSpec", "DimensionSpec", "SampleSpec", "StoreSpec", "ExecutionSpec",
           "Sweep", "SweepPlan", "Parameter", "load_sweep", "parse_sweep", "run_seeds",
           "DEFAULT_SIGNALS", "STORE_FORMAT"]

#: Store layout version (part of the sweep hash).
STORE_FORMAT = 1
#: The paper's three diagnosed signals (Xue & Howard, section 4.2).
DEFAULT_SIGNALS = ("v_yg", "omega_p", "transmission_error")

# ============================================================================================
# the sweep file
# ============================================================================================
class _SweepModel(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


Scalar = bool | int | float | str



class RangeSpec(_SweepModel):
    """A range axis: ``{start, stop, num}`` (both ends included) or ``{start, stop, step}``."""

    start: Scalar = Field(description="First value (number in SI or unit string).")
    stop: Scalar = Field(description="Last value, included (number in SI or unit string).")
    num: int | None = Field(None, ge=1, le=1_000_000, strict=True,
                            description="Number of values, ends included.")
    step: Scalar | None = Field(None, description="Step (number in SI or unit string); the "
                                                  "last value is the last one not past stop.")
    scale: Literal["linear", "log"] = Field("linear", description="Spacing of 'num' values.")

    @model_validator(mode="after")
    def _one_of(self) -> RangeSpec:
        if (self.num is None) == (self.step is None):
            raise ValueError("exactly one of 'num' or 'step'")
        if self.step is not None and self.scale == "log":
            raise ValueError("'step' with scale = 'log' (give 'num' for log spacing)")
        return self


class DimensionSpec(_SweepModel):
    """A sampled dimension: bounds and scale."""

    low: Scalar = Field(description="Lower bound (number in SI or unit string).")
    high: Scalar = Field(description="Upper bound (number in SI or unit string).")
    scale: Literal["linear", "log"] = Field("linear", description="Uniform in the value or in "
                                                                  "its logarithm.")


class SampleSpec(_SweepModel):
    """Quasi-random sampling of continuous case values (scipy.stats.qmc)."""

    method: Literal["sobol", "lhs"] = Field("sobol", description="Scrambled Sobol' or Latin "
                                                                 "hypercube.")
    n: int = Field(ge=1, le=10_000_000, strict=True, description="Number of points (Sobol': a "
                                                                 "power of two).")
    scramble: bool = Field(True, strict=True,
                           description="Sobol': Owen scrambling (needed for the seed to matter).")
    dimensions: dict[str, DimensionSpec] = Field(description="Dotted case key -> bounds.")

    @model_validator(mode="after")
    def _check(self) -> SampleSpec:
        if not self.dimensions:
            raise ValueError("at least one entry in [sample.dimensions]")
        if self.method == "sobol" and self.n & (self.n - 1):
            raise ValueError(f"a power of two for n with method = 'sobol' (got {self.n}: Sobol' "
                             "points lose their balance otherwise); use method = 'lhs' for any n")
        return self


class StoreSpec(_SweepModel):
    """What is stored per run besides status, error and timing."""

    signals: list[str] = Field(default_factory=lambda: list(DEFAULT_SIGNALS),
                               description="Simulation variables diagnosed (angle: theta_p).")
    tsa: bool = Field(False, strict=True, description="Store each signal's synchronous average.")
    raw: bool = Field(False, strict=True,
                      description="Store the recorded series (signals and theta_p).")
    noise_snr_db: float | None = Field(None, description="Add white Gaussian measurement noise "
                                                         "at this SNR [dB] to each signal, "
                                                         "seeded by the run's seed.")

    @field_validator("signals")
    @classmethod
    def _signals(cls, v: list[str]) -> list[str]:
        if not v:
            raise ValueError("at least one signal")
        if len(set(v)) != len(v):
            raise ValueError("distinct signal names")
        bad = [s for s in v if not s.isidentifier()]
        if bad:
            raise ValueError(f"variable names of the simulation result (got {bad})")
        return v

    @field_validator("noise_snr_db")
    @classmethod
    def _snr(cls, v: float | None) -> float | None:
        if v is not None and not math.isfinite(v):
            raise ValueError("a finite SNR in dB")
        return v


class ExecutionSpec(_SweepModel):
    """How runs are grouped into Dask tasks (not part of the sweep's identity)."""

    batch_size: int | Literal["auto"] = Field(
        "auto", description="Runs per task (= chunk length along 'run'); 'auto' times one run "
                            "and aims at task_seconds.")
    task_seconds: float = Field(1.0, gt=0, le=3600, description="Target task duration [s] for "
                                                                "batch_size = 'auto'.")

    @field_validator("batch_size")
    @classmethod
    def _batch(cls, v):
        if isinstance(v, int) and v < 1:
            raise ValueError("a positive number of runs, or 'auto'")
        return v


class SweepFile(_SweepModel):
    """The validated content of a sweep file (values as written; see :class:`Sweep`)."""

    name: str = Field("sweep", description="Name of the sweep.")
    description: str = Field("", description="Free text.")
    base: str | None = Field(None, description="Base case: a shipped case name (e.g. "
                                               "'xue_howard') or a case file, relative to the "
                                               "sweep file; default the paper's case.")
    seed: int = Field(0, ge=0, le=2**63 - 1, strict=True, description="Seed of the sampling "
                                                                      "and of the per-run seeds.")
    set: dict[str, Any] = Field(default_factory=dict, description="Fixed overrides of the base "
                                                                  "case (dotted keys).")
    link: dict[str, str] = Field(default_factory=dict, description="Dotted key -> swept key "
                                                                   "whose value it takes.")
    axes: dict[str, list[Scalar] | RangeSpec] = Field(
        default_factory=dict, description="Dotted key -> values (list) or range; full factorial.")
    sample: SampleSpec | None = Field(None, description="Sampled dimensions.")
    store: StoreSpec = Field(default_factory=StoreSpec)
    execution: ExecutionSpec = Field(default_factory=ExecutionSpec)

    @model_validator(mode="before")
    @classmethod
    def _flatten(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        data = dict(data)
        for name in ("set", "link"):
            if isinstance(data.get(name), dict):
                data[name] = _flatten(data[name], lambda v: not isinstance(v, dict))
        if isinstance(data.get("axes"), dict):
            data["axes"] = _flatten(data["axes"], lambda v: not isinstance(v, dict) or bool(
                set(v) & {"start", "stop", "num", "step"}))
        sample = data.get("sample")
        if isinstance(sample, dict) and isinstance(sample.get("dimensions"), dict):
            data["sample"] = {**sample, "dimensions": _flatten(
                sample["dimensions"], lambda v: not isinstance(v, dict) or bool(
                    set(v) & {"low", "high"}))}
        return data


def _flatten(tree: dict, is_leaf: Callable[[Any], bool], prefix: str = "") -> dict:
    """``{"crack": {"depth": v}}`` -> ``{"crack.depth": v}`` (TOML dotted keys), stopping at
    leaves; quoted keys (``"crack.depth" = v``) pass through unchanged."""
    out: dict[str, Any] = {}
    for k, v in tree.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if is_leaf(v):
            out[key] = v
        else:
            out.update(_flatten(v, is_leaf, key))
    return out


_TYPE_LOCS = ("function-", "list[", "literal[", "RangeSpec", "DimensionSpec", "int", "str",
              "bool", "float")


def _field_path(loc: Sequence) -> str:
    """A pydantic error location as a sweep-file field: ``axes.crack.depth[1]`` (the union
    branch names pydantic inserts are dropped)."""
    out = ""
    for p in loc:
        if isinstance(p, int):
            out += f"[{p}]"
        elif not str(p).startswith(_TYPE_LOCS) or str(p) in SweepFile.model_fields:
            out += f".{p}" if out else str(p)
    return out or "sweep"


def _format_sweep_error(exc: ValidationError) -> InputError:
    """The first pydantic error as an :class:`InputError` naming the sweep-file field."""
    errs = exc.errors(include_url=False)
    # in a union (a list or a range), report the branch matching what was written
    wrong_branch = {"list_type", "model_type", "dict_type", "model_attributes_type"}
    errs = sorted(errs, key=lambda e: e["type"] in wrong_branch)
    first = errs[0]
    field_name = _field_path(first["loc"])
    msg = first["msg"]
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    same = [e for e in errs if _field_path(e["loc"]) == field_name]
    scalar_union = {"bool_type", "int_type", "float_type", "string_type", "bool_parsing",
                    "int_parsing", "float_parsing"}
    if len({e["type"] for e in same} & scalar_union) > 1:
        msg = "a number, a string with a unit, true/false or a string (one value)"
    if first["type"] == "extra_forbidden":
        parent = _model_at(first["loc"][:-1])
        allowed = sorted(parent.model_fields) if parent is not None else []
        msg = "a known key; allowed keys here: " + ", ".join(allowed)
    elif first["type"] == "missing":
        msg = "a value (this required field is missing)"
    others = len({_field_path(e["loc"]) for e in errs} - {field_name})
    more = f" (and {others} more problem{'s' if others > 1 else ''})" if others else ""
    value = None if first["type"] == "missing" else first.get("input")
    return InputError(field_name, value, msg + more)


def _model_at(loc: Sequence) -> type[BaseModel] | None:
    """The sweep-file model at an error location (for the list of allowed keys), if any."""
    parts = [str(p) for p in loc if not isinstance(p, int)
             and (not str(p).startswith(_TYPE_LOCS) or str(p) in SweepFile.model_fields)]
    model: type[BaseModel] = SweepFile
    i = 0
    while i < len(parts):
        f = model.model_fields.get(parts[i])
        if f is None:
            return None
        ann = _strip_optional(f.annotation)
        if typing.get_origin(ann) is dict:  # axes, dimensions: the next part is a dotted key
            ann = typing.get_args(ann)[1]
            i += 1
        subs = [a for a in typing.get_args(ann) or (ann,)
                if isinstance(a, type) and issubclass(a, BaseModel)]
        if not subs:
            return None
        model = subs[0]
        i += 1
    return model


# --------------------------------------------------------------------------------------------
# what a dotted key of the case is
# --------------------------------------------------------------------------------------------
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
    for i, p in enumerate(parts):
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


# --------------------------------------------------------------------------------------------
# the resolved sweep and its expansion
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Parameter:
    """A case value that changes from run to run (a coordinate of the store).

    Attributes
    ----------
    key : str
        Dotted case key.
    kind : {"float", "int", "bool", "str"}
        Value type.
    units : str
        SI unit of the values (``"1"`` dimensionless, ``""`` for booleans and strings).
    long_name : str
        Description (the case field's).
    role : str
        ``"axis"``, ``"sample"`` or ``"link"``.
    source : str
        For a link, the swept key it follows; else the key itself.
    """

    key: str
    kind: str
    units: str
    long_name: str
    role: str
    source: str


@dataclass(frozen=True)
class SweepPlan:
    """The expanded sweep: every run's parameter values and seed.

    Attributes
    ----------
    n_runs : int
        Number of runs [-].
    parameters : tuple of Parameter
        Swept, sampled and linked keys, in file order (axes, then sampled, then links).
    values : dict of str to ndarray
        Per key, the value of every run (SI), shape (n_runs,).
    seeds : ndarray of int64
        Per-run seed: ``SeedSequence(seed, spawn_key=(run,))``'s first 32-bit word.
    grid_shape : tuple of int
        Number of values of each axis (empty without axes).
    n_samples : int
        Sampled points per grid point (1 without sampling).
    unit_points : ndarray or None
        The quasi-random points in the unit cube, shape (n_samples, n_dimensions).
    """

    n_runs: int
    parameters: tuple[Parameter, ...]
    values: dict[str, np.ndarray]
    seeds: np.ndarray
    grid_shape: tuple[int, ...]
    n_samples: int
    unit_points: np.ndarray | None = None

    def overrides(self, run: int) -> dict[str, Any]:
        """The case overrides of one run (dotted key -> Python scalar, SI)."""
        return {p.key: self.values[p.key][run].item() for p in self.parameters}


@dataclass(frozen=True)
class _Axis:
    key: str
    field: _CaseField
    values: list[Any]


@dataclass(frozen=True)
class _Dimension:
    key: str
    field: _CaseField
    low: float
    high: float
    scale: str


@dataclass(frozen=True)
class Sweep:
    """A validated sweep: the file's content, the base case and the resolved axes.

    Build with :func:`load_sweep` or :func:`parse_sweep`; expand with :meth:`plan`.

    Attributes
    ----------
    spec : SweepFile
        The file's validated content.
    base_case : geardyn.config.Case
        The base case with ``[set]`` applied.
    text : str
        The sweep file's text (stored in the Zarr attributes).
    origin : str
        Where it came from (a path or ``"<string>"``).
    """

    spec: SweepFile
    base_case: Case
    text: str
    origin: str
    axes: tuple[_Axis, ...]
    dimensions: tuple[_Dimension, ...]
    links: dict[str, str]

    @property
    def n_runs(self) -> int:
        """Number of runs [-]."""
        n = math.prod(len(a.values) for a in self.axes)
        return n * (self.spec.sample.n if self.spec.sample else 1)

    def definition(self) -> dict:
        """Everything the results depend on, as plain JSON-able data (hashed for the store)."""
        from ... import __version__

        sample = None
        if self.spec.sample is not None:
            s = self.spec.sample
            sample = {"method": s.method, "n": s.n, "scramble": s.scramble,
                      "dimensions": [[d.key, d.low, d.high, d.scale] for d in self.dimensions]}
        return {
            "store_format": STORE_FORMAT,
            "geardyn": __version__,
            "seed": self.spec.seed,
            "base_case": deep_copy_case_data(self.base_case),
            "axes": [[a.key, a.values] for a in self.axes],
            "sample": sample,
            "link": sorted(self.links.items()),
            "store": self.spec.store.model_dump(mode="json"),
        }

    def plan(self) -> SweepPlan:
        """Expand the sweep into runs (full factorial of the axes x the sampled points).

        The sampled points are the same for every grid point (a crossed design), drawn with
        ``scipy.stats.qmc.Sobol(d, scramble=..., rng=seed)`` (``random_base2``) or
        ``qmc.LatinHypercube(d, rng=seed)`` and mapped to ``low + u (high - low)`` (linear) or
        ``low (high/low)^u`` (log).
        """
        grid_shape = tuple(len(a.values) for a in self.axes)
        n_grid = math.prod(grid_shape)
        n_samples = self.spec.sample.n if self.spec.sample else 1
        n_runs = n_grid * n_samples
        values: dict[str, np.ndarray] = {}
        params: list[Parameter] = []
        idx = np.indices(grid_shape).reshape(len(grid_shape), -1) if grid_shape else None
        for i, a in enumerate(self.axes):
            arr = _typed_array(a.values, a.field)[idx[i]]
            values[a.key] = np.repeat(arr, n_samples)
            params.append(Parameter(a.key, a.field.kind, a.field.units, a.field.description,
                                    "axis", a.key))
        unit = None
        if self.spec.sample is not None:
            unit = _unit_points(self.spec.sample, len(self.dimensions), self.spec.seed)
            for j, d in enumerate(self.dimensions):
                u = unit[:, j]
                if d.scale == "log":
                    v = d.low * (d.high / d.low) ** u
                else:
                    v = d.low + u * (d.high - d.low)
                values[d.key] = np.tile(np.clip(v, d.low, d.high), n_grid)
                params.append(Parameter(d.key, "float", d.field.units, d.field.description,
                                        "sample", d.key))
        for key, src in self.links.items():
            fld = _case_field(key, f"link.{key}")
            values[key] = values[src].copy()
            params.append(Parameter(key, fld.kind, fld.units, fld.description, "link", src))
        seeds = run_seeds(self.spec.seed, n_runs)
        return SweepPlan(n_runs, tuple(params), values, seeds, grid_shape, n_samples, unit)


def run_seeds(seed: int, n: int, start: int = 0) -> np.ndarray:
    """Per-run seeds: the first 32-bit word of ``SeedSequence(seed, spawn_key=(run,))``.

    Independent of the number of runs, so a run's seed never depends on the rest of the sweep.
    """
    return np.array([np.random.SeedSequence(seed, spawn_key=(r,)).generate_state(1)[0]
                     for r in range(start, start + n)], dtype=np.int64)


def _unit_points(s: SampleSpec, d: int, seed: int) -> np.ndarray:
    from scipy.stats import qmc

    if s.method == "sobol":
        eng = qmc.Sobol(d, scramble=s.scramble, rng=seed)
        return eng.random_base2(int(round(math.log2(s.n))))
    return qmc.LatinHypercube(d, rng=seed).random(s.n)


def _typed_array(values: list[Any], fld: _CaseField) -> np.ndarray:
    if fld.kind == "float":
        return np.asarray(values, dtype=np.float64)
    if fld.kind == "int":
        return np.asarray(values, dtype=np.int64)
    if fld.kind == "bool":
        return np.asarray(values, dtype=bool)
    return np.asarray(values, dtype=str)


def _range_values(r: RangeSpec, fld: _CaseField, where: str) -> list[Any]:
    if fld.kind not in ("float", "int"):
        raise InputError(where, r.model_dump(exclude_none=True),
                         "a list of values (ranges need a numeric case value)")
    start = _convert(fld, r.start, f"{where}.start") if fld.kind == "int" else \
        to_si(r.start, fld.dimension or "dimensionless", f"{where}.start")
    stop = _convert(fld, r.stop, f"{where}.stop") if fld.kind == "int" else \
        to_si(r.stop, fld.dimension or "dimensionless", f"{where}.stop")
    if r.num is not None:
        if r.scale == "log":
            if not (start > 0 and stop > 0):
                raise InputError(f"{where}.start", r.start, "positive start and stop for "
                                                            "scale = 'log'")
            vals = np.geomspace(start, stop, r.num)
        else:
            vals = np.linspace(start, stop, r.num)
        if fld.kind == "int":
            if not np.allclose(vals, np.round(vals)):
                raise InputError(f"{where}.num", r.num, f"a count giving whole numbers from "
                                                        f"{start} to {stop} ({fld.key} is an "
                                                        "integer); or give 'step'")
            return [int(round(v)) for v in vals]
        return [float(v) for v in vals]
    step = _convert(fld, r.step, f"{where}.step") if fld.kind == "int" else \
        to_si(r.step, fld.dimension or "dimensionless", f"{where}.step")
    if step == 0 or (stop - start) * step < 0:
        raise InputError(f"{where}.step", r.step, "a non-zero step going from start towards stop")
    n = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
    if n > 1_000_000:
        raise InputError(f"{where}.step", r.step, "a step giving at most 1,000,000 values")
    if fld.kind == "int":
        return [int(start + k * step) for k in range(n)]
    return [float(start + k * step) for k in range(n)]


# --------------------------------------------------------------------------------------------
# loading
# --------------------------------------------------------------------------------------------
def load_sweep(path: str | os.PathLike) -> Sweep:
    """Read and validate a sweep file.

    Parameters
    ----------
    path : path-like
        The TOML sweep file (a relative ``base`` case file is taken relative to its folder), or
        the name of a sweep shipped with geardyn (``crack_torque_bearing`` for
        ``geardyn/cases/sweep_crack_torque_bearing.toml``).

    Returns
    -------
    Sweep

    Raises
    ------
    DataFileError
        Missing or unreadable file, or not valid TOML.
    InputError
        A bad key or value; the message names the field (e.g. ``axes.crack.depth[2]``), the
        value and what is allowed.
    """
    p = Path(path)
    if not p.exists() and p.parent == Path(".") and p.suffix in ("", ".toml"):
        stem = p.stem if p.stem.startswith("sweep_") else f"sweep_{p.stem}"
        shipped = resources.files("geardyn.cases").joinpath(f"{stem}.toml")
        if shipped.is_file():
            p = Path(str(shipped))
    from ...io import read_text

    text = read_text(p, "sweep file")
    return parse_sweep(text, base_dir=p.parent, origin=str(p))


def parse_sweep(text: str, *, base_dir: str | os.PathLike | None = None,
                origin: str = "<string>") -> Sweep:
    """Validate sweep-file text (see the module docstring for the format).

    Parameters
    ----------
    text : str
        TOML text.
    base_dir : path-like, optional
        Folder a relative ``base`` case file is resolved against (default: the current one).
    origin : str
        Name used in messages.

    Returns
    -------
    Sweep
    """
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DataFileError(origin, f"is not valid TOML: {exc}") from None
    try:
        spec = SweepFile.model_validate(raw)
    except ValidationError as exc:
        raise _format_sweep_error(exc) from None
    return _resolve(spec, text, origin, Path(base_dir) if base_dir is not None else Path.cwd())


def _load_base(spec: SweepFile, base_dir: Path) -> Case:
    base = spec.base
    overrides = dict(spec.set)
    for key in overrides:
        _case_field(key, f"set.{key}")
    try:
        if base is None:
            return load_case(None, overrides)
        shipped = resources.files("geardyn.cases").joinpath(f"{base}.toml")
        if "/" not in base and not base.endswith(".toml") and shipped.is_file():
            return load_case(Path(str(shipped)), overrides)
        path = Path(base)
        if not path.is_absolute():
            path = base_dir / path
        if not path.exists():
            names = sorted(f.name[:-5] for f in resources.files("geardyn.cases").iterdir()
                           if f.name.endswith(".toml") and not f.name.startswith("sweep_"))
            raise InputError("base", base, "a case file (relative to the sweep file) or a "
                                           f"shipped case: {', '.join(names)}")
        return load_case(path, overrides)
    except InputError as exc:
        if exc.field in overrides:
            raise InputError(f"set.{exc.field}", exc.value, exc.allowed) from None
        raise


def _resolve(spec: SweepFile, text: str, origin: str, base_dir: Path) -> Sweep:
    base = _load_base(spec, base_dir)
    if not spec.axes and spec.sample is None:
        raise InputError("axes", {}, "at least one axis ([axes]) or sampled dimension "
                                     "([sample.dimensions])")
    seen: dict[str, str] = {k: "set" for k in spec.set}
    axes: list[_Axis] = []
    for key, spec_values in spec.axes.items():
        where = f"axes.{key}"
        fld = _case_field(key, where)
        if key in seen:
            raise InputError(where, key, f"a key not already given in [{seen[key]}]")
        seen[key] = "axes"
        if isinstance(spec_values, RangeSpec):
            vals = _range_values(spec_values, fld, where)
        else:
            if not spec_values:
                raise InputError(where, [], "a non-empty list of values")
            vals = [_convert(fld, v, f"{where}[{i}]") for i, v in enumerate(spec_values)]
        if len({(type(v), v) for v in vals}) != len(vals):
            raise InputError(where, spec_values if not isinstance(spec_values, RangeSpec)
                             else spec_values.model_dump(exclude_none=True), "distinct values")
        axes.append(_Axis(key, fld, vals))
    dims: list[_Dimension] = []
    if spec.sample is not None:
        for key, d in spec.sample.dimensions.items():
            where = f"sample.dimensions.{key}"
            fld = _case_field(key, where)
            if key in seen:
                raise InputError(where, key, f"a key not already given in [{seen[key]}]")
            seen[key] = "sample.dimensions"
            if fld.kind != "float":
                raise InputError(where, key, "a continuous case value (a number); sweep whole "
                                             "numbers, booleans and choices in [axes]")
            lo = to_si(d.low, fld.dimension or "dimensionless", f"{where}.low")
            hi = to_si(d.high, fld.dimension or "dimensionless", f"{where}.high")
            if not lo < hi:
                raise InputError(f"{where}.high", d.high, f"a value above low ({d.low!r})")
            if d.scale == "log" and lo <= 0:
                raise InputError(f"{where}.low", d.low, "a positive bound for scale = 'log'")
            dims.append(_Dimension(key, fld, lo, hi, d.scale))
    links: dict[str, str] = {}
    swept = {a.key: a.field for a in axes} | {d.key: d.field for d in dims}
    for key, src in spec.link.items():
        where = f"link.{key}"
        fld = _case_field(key, where)
        if key in seen:
            raise InputError(where, key, f"a key not already given in [{seen[key]}]")
        if src not in swept:
            raise InputError(where, src, "a key swept in [axes] or [sample.dimensions]: "
                                         + ", ".join(swept))
        if fld.kind != swept[src].kind or fld.dimension != swept[src].dimension:
            raise InputError(where, src, f"a swept key of the same kind and unit as {key} "
                                         f"({fld.units or fld.kind})")
        seen[key] = "link"
        links[key] = src
    _check_store_compatible(spec.store, set(seen) - set(spec.set))
    sweep = Sweep(spec, base, text, origin, tuple(axes), tuple(dims), links)
    _check_values(sweep)
    return sweep


def _check_store_compatible(store: StoreSpec, swept: set[str]) -> None:
    if store.tsa and "diagnostics.samples_per_rev" in swept:
        raise InputError("store.tsa", True, "false when diagnostics.samples_per_rev is swept "
                                            "(the stored averages must share one length)")
    if store.raw:
        bad = swept & {"simulation.dt", "simulation.record_time", "simulation.decimation"}
        if bad:
            raise InputError("store.raw", True, f"false when {', '.join(sorted(bad))} is swept "
                                                "(the stored series must share one time axis)")


def _check_values(sweep: Sweep) -> None:
    """Validate every axis value and sampled bound with the other keys at their first value.

    Each check builds the case (``Case.with_overrides``), so a value the case refuses (negative
    stiffness, teeth out of range...) is an error naming its place in the sweep file. Runs that
    only fail in combination, or later (geometry, time step, divergence), are recorded as failed
    runs instead.
    """
    first: dict[str, Any] = {a.key: a.values[0] for a in sweep.axes}
    first |= {d.key: d.low for d in sweep.dimensions}

    def check(key: str, value: Any, where: str) -> None:
        ov = {**first, key: value}
        ov |= {k: ov[src] for k, src in sweep.links.items()}
        try:
            sweep.base_case.with_overrides(ov)
        except InputError as exc:
            raise InputError(where, value, f"{exc.allowed} (from the case: {exc.field})"
                             ) from None

    for a in sweep.axes:
        for i, v in enumerate(a.values):
            check(a.key, v, f"axes.{a.key}[{i}]")
    for d in sweep.dimensions:
        check(d.key, d.low, f"sample.dimensions.{d.key}.low")
        check(d.key, d.high, f"sample.dimensions.{d.key}.high")


