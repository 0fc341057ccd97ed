"""Loading a sweep file: validation, the base case, the run-count bound, the resolved axes.

The schema of the file is in :mod:`.schema`, what a dotted case key is in :mod:`.case_keys`, the
resolved sweep and its expansion into runs in :mod:`.plan`; their public names are importable
from here too. See :mod:`geardyn.studies.sweep` for the format. Quantities take unit strings and are converted
with the unit handling of :mod:`geardyn.config` (:func:`geardyn.units.to_si` with the dimension
of the case field a dotted key names); every value is checked by building the case with
:meth:`geardyn.config.Case.with_overrides`.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from ...config import Case, load_case
from ...errors import DataFileError, InputError
from ...units import to_si
from .case_keys import _case_field, _convert
from .plan import STORE_FORMAT, Parameter, Sweep, SweepPlan, _Axis, _Dimension, _range_values, run_seeds
from .schema import (
    DEFAULT_SIGNALS,
    DimensionSpec,
    ExecutionSpec,
    RangeSpec,
    SampleSpec,
    StoreSpec,
    SweepFile,
    _format_sweep_error,
)
from .signals import check_demodulation_band, check_record_length, check_sweep_signals

__all__ = ["SweepFile", "RangeSpec", "DimensionSpec", "SampleSpec", "StoreSpec", "ExecutionSpec",
           "Sweep", "SweepPlan", "Parameter", "load_sweep", "parse_sweep", "run_seeds",
           "DEFAULT_SIGNALS", "STORE_FORMAT", "DEFAULT_MAX_RUNS", "max_runs_limit"]


#: Default largest number of runs of a sweep (``max_runs``; ``$GEARDYN_MAX_RUNS`` changes it).
DEFAULT_MAX_RUNS = 100_000
#: Axes longer than this have only their first, last, smallest and largest values checked by
#: building the case (about 2 ms each); every value is still converted and type-checked.
_CHECK_ALL_UP_TO = 200


def max_runs_limit(max_runs: int | None = None) -> int:
    """The run-count limit: ``max_runs``, else ``$GEARDYN_MAX_RUNS``, else
    :data:`DEFAULT_MAX_RUNS`."""
    if max_runs is not None:
        if isinstance(max_runs, bool) or not isinstance(max_runs, int) or max_runs < 1:
            raise InputError("--max-runs", max_runs, "a positive whole number of runs")
        return max_runs
    env = os.environ.get("GEARDYN_MAX_RUNS", "").strip()
    if not env:
        return DEFAULT_MAX_RUNS
    try:
        value = int(env.replace("_", ""))
    except ValueError:
        value = 0
    if value < 1:
        raise InputError("GEARDYN_MAX_RUNS", env[:40], "a positive whole number of runs")
    return value


def _check_run_count(n_grid: int, n_samples: int, limit: int, what: str) -> None:
    n = n_grid * n_samples
    if n > limit:
        raise InputError(what, f"{n:,} runs", f"at most {limit:,} runs (the limit; raise it with "
                                              "--max-runs N or GEARDYN_MAX_RUNS=N, or "
                                              "max_runs= in load_sweep/parse_sweep)")


def load_sweep(path: str | os.PathLike, *, max_runs: int | None = None) -> Sweep:
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
    return parse_sweep(text, base_dir=p.parent, origin=str(p), max_runs=max_runs)


def parse_sweep(text: str, *, base_dir: str | os.PathLike | None = None,
                origin: str = "<string>", max_runs: int | None = None) -> Sweep:
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
    return _resolve(spec, text, origin, Path(base_dir) if base_dir is not None else Path.cwd(),
                    max_runs_limit(max_runs))


def _load_base(spec: SweepFile, base_dir: Path) -> Case:
    base = spec.base
    overrides = dict(spec.set)
    for key in overrides:
        _case_field(key, f"set.{key}")
    try:
        if base is None:
            return load_case(None, overrides, override_source="sweep file [set]")
        shipped = resources.files("geardyn.cases").joinpath(f"{base}.toml")
        if "/" not in base and not base.endswith(".toml") and shipped.is_file():
            return load_case(Path(str(shipped)), overrides, override_source="sweep file [set]")
        path = Path(base)
        if not path.is_absolute():
            path = base_dir / path
        if not path.exists():
            names = sorted(f.name[:-5] for f in resources.files("geardyn.cases").iterdir()
                           if f.name.endswith(".toml") and not f.name.startswith("sweep_"))
            raise InputError("base", base, "a case file (relative to the sweep file) or a "
                                           f"shipped case: {', '.join(names)}")
        return load_case(path, overrides, override_source="sweep file [set]")
    except InputError as exc:
        key = re.sub(r"\[(\d+)\]", r".\1", str(exc.field))  # faults[0].width: faults.0.width
        if key in overrides:  # named as the sweep file's [set] table names it
            raise InputError(f"set.{key}", exc.value, exc.allowed) from None
        raise


def _resolve(spec: SweepFile, text: str, origin: str, base_dir: Path,
             limit: int = DEFAULT_MAX_RUNS) -> Sweep:
    # the run count before any value is expanded (ranges with 'step' counted once resolved)
    n_samples = spec.sample.n if spec.sample else 1
    known = math.prod(v.num if isinstance(v, RangeSpec) and v.num is not None else
                      len(v) if isinstance(v, list) else 1 for v in spec.axes.values())
    _check_run_count(known, n_samples, limit, "axes" if spec.axes else "sample.n")
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
        _check_run_count(math.prod(len(a.values) for a in axes), n_samples, limit, where)
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
    check_runnable(sweep, record=False)
    return sweep


def check_runnable(sweep: Sweep, *, record: bool = True) -> None:
    """The checks of what every run would find the same, before any run: signals the sweep's
    model records, a demodulation band the runs can use and, with ``record``, a record long
    enough to average (see :mod:`.signals`). Loading a sweep file checks all but the record
    length, which only the standard evaluator needs (its TSA): :func:`~.execute.run_sweep`
    checks it before starting the cluster; a study's own evaluator (e.g. the model-II study's
    RMS differences) may take shorter records."""
    check_sweep_signals(sweep, sweep.spec.store.signals)
    if record:
        check_record_length(sweep)
    check_demodulation_band(sweep)


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
    stiffness, teeth out of range...) is an error naming its place in the sweep file. An axis of
    more than ``_CHECK_ALL_UP_TO`` values has its first, last, smallest and largest values
    checked (the case's checks are ranges), so the check stays bounded in time. Runs that
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
        for i in _indices_to_check(a.values):
            check(a.key, a.values[i], f"axes.{a.key}[{i}]")
    for d in sweep.dimensions:
        check(d.key, d.low, f"sample.dimensions.{d.key}.low")
        check(d.key, d.high, f"sample.dimensions.{d.key}.high")




def _indices_to_check(values: list[Any]) -> list[int]:
    """Every index of a short axis; of a long one (more than ``_CHECK_ALL_UP_TO`` values) the
    first, last, smallest and largest (numbers), which bound what the case's range checks see."""
    n = len(values)
    if n <= _CHECK_ALL_UP_TO:
        return list(range(n))
    idx = {0, n - 1}
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        arr = np.asarray(values, dtype=np.float64)
        idx |= {int(np.argmin(arr)), int(np.argmax(arr))}
    else:
        idx |= set(range(min(n, _CHECK_ALL_UP_TO)))
    return sorted(idx)
