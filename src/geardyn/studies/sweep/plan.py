"""The resolved sweep (:class:`Sweep`) and its expansion into runs (:class:`SweepPlan`): the
full factorial of the axes crossed with the quasi-random points, per-run seeds and values."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...config import Case, deep_copy_case_data
from ...errors import InputError
from ...units import to_si
from .case_keys import _case_field, _CaseField, _convert
from .schema import RangeSpec, SampleSpec, SweepFile

__all__ = ["Sweep", "SweepPlan", "Parameter", "run_seeds", "STORE_FORMAT"]

#: Store layout version (part of the sweep hash). 2: per-batch checksums (``batch_checksum``).
STORE_FORMAT = 2


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
        from ..._version import __version__

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
