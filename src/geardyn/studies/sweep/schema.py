"""The sweep file's schema: pydantic models of its sections and their error messages.

See :mod:`geardyn.studies.sweep` for the format. Values are kept as written (numbers in SI or unit
strings); :mod:`.spec` converts and checks them against the case.
"""

from __future__ import annotations

import math
import typing
from collections.abc import Callable, Sequence
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ...errors import InputError
from .case_keys import _strip_optional

__all__ = ["SweepFile", "RangeSpec", "DimensionSpec", "SampleSpec", "StoreSpec", "ExecutionSpec",
           "DEFAULT_SIGNALS"]

#: The paper's three diagnosed signals (Xue & Howard, section 4.2).
DEFAULT_SIGNALS = ("v_yg", "omega_p", "transmission_error")


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
                               description="Simulation variables diagnosed (angle: theta_p): "
                                           "names of signals.RECORD_SIGNALS.")
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
        return v  # names the record lacks: signals.check_signal_names (named, when loaded)

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
    task_seconds: float = Field(5.0, gt=0, le=3600, description="Target task duration [s] for "
                                                                "batch_size = 'auto' (a batch's "
                                                                "chunk writes are 1-3 % of a 5 s "
                                                                "task).")

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
