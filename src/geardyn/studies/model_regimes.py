r"""Where the centre-distance dynamics matter: model II against model I-static over a sweep.

Model II evaluates the mesh stiffness at the operating centre distance ``d(t)`` iterated every
step (Xue & Howard 2018, Fig. 7); model I-static holds it at the static operating centre distance
of eq. 4 (:data:`geardyn.dynamics.model.MODELS`). The two differ *only* through the dynamics of
the centre distance, so ``RMS(II - I-static) / STD(II)`` of a signal measures how much those
dynamics change it (issue 18, item 4). This module adds no physics: every number comes from
:func:`geardyn.dynamics.simulate` and :func:`geardyn.stiffness.build_map`.

The grid is a sweep file (:mod:`geardyn.studies.sweep`), shipped as
``geardyn/cases/sweep_model_regimes.toml`` (and ``sweep_model_regimes_quick.toml``), with axes

* ``crack.depth`` [m] (0: the healthy tooth),
* ``pinion.bearing_damping_ratio`` [-] (``q_y = 2 zeta sqrt(k m)``; the gear's linked to it),
* ``pinion.bearing_stiffness`` [N/m] (the gear's linked to it),
* ``load.speed`` [rad/s] (the target mean pinion speed; the output law is calibrated to it),

run on Dask into a resumable Zarr store by :func:`geardyn.studies.sweep.run_sweep` with
:class:`ModelRegimeEvaluator`. Each run (:func:`compare_point`) simulates model II and model
I-static on the same case and the same stiffness map, and model II again with the paper's
start-of-step stiffness evaluation (``simulation.stiffness_evaluation = "start"``, the flow chart
of Fig. 7) beside geardyn's predictor evaluation, and records the model II iteration counts of
both. :func:`model_regimes` runs the sweep and returns one Dataset over the four axes, which
:mod:`geardyn.studies.model_regimes_report` turns into figures and a short HTML page.

Per run:

* **settling time** ``max(case settle_time, 3 tau)``, ``tau = 1 / sigma`` the decay time of the
  centre-distance mode (:func:`centre_distance_modes`), so a lightly damped bearing mode has
  decayed to ``exp(-3) = 5 %`` of its start-up amplitude before recording;
* **recorded time**: a whole number of pinion revolutions, at least 2 and at least the case's
  ``record_time`` (a crack passes the mesh the same number of times a revolution in every
  record);
* a point whose *static* operating centre distance (eq. 4) lies outside the map (the map ends
  where the contact ratio falls to 1) is not simulated (status :data:`NOT_RUN`);
* a run that fails numerically (:class:`geardyn.errors.NumericalError`) records the kernel's
  status code (:data:`STATUS_NAMES`) and NaN metrics; the other runs of the point go on.

References
----------
Xue, S. & Howard, I. (2018). Dynamic modelling of flexibly supported gears using iterative
convergence of tooth mesh stiffness. Mech. Syst. Signal Process. (eq. 4, Fig. 7, section 4).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import GeardynError, InputError, NumericalError
from .sweep.evaluate import Evaluator, Output

__all__ = ["model_regimes", "load_study_sweep", "ModelRegimeEvaluator", "compare_point",
           "evaluation_convergence", "point_case", "centre_distance_modes", "study_case",
           "SIGNALS", "MAIN_SIGNALS", "STATUS_NAMES", "NOT_RUN", "THRESHOLD", "AXES",
           "SWEEP", "QUICK_SWEEP"]

#: Signals compared (record variables of :func:`geardyn.dynamics.simulate`).
SIGNALS = ("transmission_error", "mesh_force", "v_yg", "omega_p", "y_g",
           "centre_distance_change", "mesh_stiffness")
#: Signals whose largest ratio is the headline ``ratio_max``: the paper's measured quantities
#: (gear centre velocity, pinion speed, transmission error) and the dynamic mesh force.
#: ``mesh_stiffness`` (the cause of the difference) and the displacements are kept per signal.
MAIN_SIGNALS = ("transmission_error", "mesh_force", "v_yg", "omega_p")
#: The threshold of issue 18: the models "differ" where the ratio exceeds 10 %.
THRESHOLD = 0.10
#: Status of a run that was not simulated (static operating point outside the map).
NOT_RUN = -1
#: Run status codes: 0 ok, -1 not run, 1-5 the kernel's failure codes, 9 another error.
STATUS_NAMES = {
    0: "ok",
    NOT_RUN: "not run: static centre distance outside the map (contact ratio < 1)",
    1: "diverged (NaN or infinite)",
    2: "runaway mesh deflection or tooth separation",
    3: "runaway bearing displacement",
    4: "centre distance left the stiffness map (contact ratio < 1)",
    5: "model II centre-distance iteration did not converge",
    9: "other error",
}
#: The study's axes: dotted case key -> (dimension name of the result, unit, long name).
AXES = {
    "crack.depth": ("crack_depth", "m", "root crack depth (0: the healthy tooth)"),
    "pinion.bearing_damping_ratio": ("damping_ratio", "1", "bearing damping ratio, q_y = 2 zeta "
                                                           "sqrt(k m) (both bearings)"),
    "pinion.bearing_stiffness": ("bearing_stiffness", "N/m", "bearing stiffness (both "
                                                             "bearings)"),
    "load.speed": ("pinion_speed", "rad/s", "target mean pinion speed"),
}
_LINKS = {"pinion.bearing_damping_ratio": "gear.bearing_damping_ratio",
          "pinion.bearing_stiffness": "gear.bearing_stiffness"}
#: The shipped sweeps (``geardyn/cases/sweep_<name>.toml``).
SWEEP = "model_regimes"
QUICK_SWEEP = "model_regimes_quick"
_RUNS = ("ii", "i_static", "ii_start")
#: The per-run rules (part of the evaluator's identity: a store made under other rules is not
#: resumed by mistake).
RULES = ("settle_time = max(case settle_time, 3 / mode_decay_rate) in whole time steps; "
         "record_time = whole pinion revolutions, >= 2 and >= the case's record_time; runs whose "
         "static centre distance lies outside the map are not simulated")
_SCALARS = {
    "status_ii": ("1", "status of the model II run (predictor evaluation): 0 ok, -1 not run, "
                       "else the failure code (STATUS_NAMES)"),
    "status_i_static": ("1", "status of the model I-static run (codes as status_ii)"),
    "status_ii_start": ("1", "status of the model II run with start-of-step evaluation (codes "
                             "as status_ii)"),
    "iterating_fraction": ("1", "model II (predictor): fraction of recorded steps with at least "
                                "one centre-distance re-solve"),
    "mean_iterations": ("1", "model II (predictor): mean re-solves per recorded step"),
    "max_iterations": ("1", "model II (predictor): most re-solves in a recorded step"),
    "steps_without_fixed_point": ("1", "model II (predictor): recorded steps accepted without a "
                                       "fixed point (handover between the iterated distances)"),
    "start_iterating_fraction": ("1", "model II (start-of-step evaluation, paper Fig. 7): "
                                      "fraction of recorded steps with at least one re-solve"),
    "start_mean_iterations": ("1", "model II (start-of-step): mean re-solves per recorded step"),
    "start_max_iterations": ("1", "model II (start-of-step): most re-solves in a recorded step"),
    "start_steps_without_fixed_point": ("1", "model II (start-of-step): recorded steps accepted "
                                             "without a fixed point"),
    "static_centre_distance_change": ("m", "static operating minus design centre distance "
                                           "(eq. 4)"),
    "centre_distance_std": ("m", "model II: standard deviation of the centre distance change"),
    "centre_distance_min": ("m", "model II: smallest centre distance change recorded"),
    "centre_distance_max": ("m", "model II: largest centre distance change recorded"),
    "separation_fraction": ("1", "model II: fraction of recorded steps with the teeth "
                                 "separated"),
    "settle_time": ("s", "simulated time discarded before recording (max of the case's and 3 "
                         "decay times of the centre-distance mode)"),
    "record_time": ("s", "recorded time (whole pinion revolutions, >= 2)"),
    "mode_frequency": ("Hz", "centre-distance mode: lowest linear mode carrying >= 10 % of the "
                             "static centre-distance response to the mesh force"),
    "mode_decay_rate": ("1/s", "modal decay rate phi^T C phi / 2 of the centre-distance mode"),
    "seconds": ("s", "wall time of the run's simulations"),
}


# ============================================================================================
# the study case and the case of a point
# ============================================================================================
def study_case(case=None, method: str = "pem"):
    """The study's base case: ``case`` (default the paper's) with the stiffness method and a map
    reaching the contact-ratio-1 limit of the pair.

    Sets ``stiffness.method`` (default ``"pem"``: the grid runs in minutes; ``"fe"`` builds one
    FE map per crack level, which takes far longer), ``centre_distance_max`` = the largest change
    with contact ratio >= 1 (:meth:`geardyn.geometry.GearPair.max_centre_distance_change`)
    rounded down to 10 um, ``centre_distance_min`` = the case's (at most 0) and as many map
    lines as keep the case's line spacing.

    Raises
    ------
    InputError
        The case gives absolute bearing dampings (the study sweeps the ratio) or a load law
        whose steady speed is not ``load.speed`` (the study sets the speed through it).
    """
    import geardyn

    case = geardyn.paper_case() if case is None else case
    for gear in ("pinion", "gear"):
        if getattr(case, gear).bearing_damping is not None:
            raise InputError(f"{gear}.bearing_damping", getattr(case, gear).bearing_damping,
                             "unset (the study sweeps bearing_damping_ratio)")
    if case.load.law == "table" or case.load.coefficient is not None:
        raise InputError("load.coefficient" if case.load.law != "table" else "load.law",
                         case.load.coefficient if case.load.law != "table" else "table",
                         "a load law calibrated to load.speed (no coefficient, not a table): "
                         "the study sets the pinion speed through load.speed")
    pair = case.gear_pair()
    dd_max = math.floor(pair.max_centre_distance_change() * 1e5) / 1e5
    st = case.stiffness
    dd_min = min(st.centre_distance_min, 0.0)
    spacing = (st.centre_distance_max - st.centre_distance_min) / max(st.centre_distances - 1, 1)
    n = max(st.centre_distances, int(math.ceil((dd_max - dd_min) / spacing)) + 1)
    return case.with_overrides({"stiffness.method": method, "stiffness.centre_distance_min": dd_min,
                                "stiffness.centre_distance_max": dd_max,
                                "stiffness.centre_distances": n}, source="model-II study")


def point_case(base, bearing_stiffness: float, damping_ratio: float, pinion_speed: float,
               crack_depth: float, *, settle_time: float | None = None,
               record_time: float | None = None):
    """The case of one point with both bearings alike (what a sweep run's overrides give).

    Parameters
    ----------
    base : Case
        The study case (:func:`study_case`).
    bearing_stiffness : float
        [N/m].
    damping_ratio : float
        Bearing damping ratio [-].
    pinion_speed : float
        Target mean pinion speed [rad/s].
    crack_depth : float
        [m]; 0: the healthy tooth.
    settle_time, record_time : float, optional
        [s]; default the base case's (the study's rule is applied by
        :class:`ModelRegimeEvaluator`, not here).

    Returns
    -------
    Case
    """
    ov = {"pinion.bearing_stiffness": float(bearing_stiffness),
          "gear.bearing_stiffness": float(bearing_stiffness),
          "pinion.bearing_damping_ratio": float(damping_ratio),
          "gear.bearing_damping_ratio": float(damping_ratio),
          "load.speed": float(pinion_speed), "crack.depth": float(crack_depth)}
    if settle_time is not None:
        ov["simulation.settle_time"] = float(settle_time)
    if record_time is not None:
        ov["simulation.record_time"] = float(record_time)
    return base.with_overrides(ov, source="model-II study")


# ============================================================================================
# the linear modes that move the centre distance
# ============================================================================================
def centre_distance_modes(dyn, k_mb: float | None = None) -> dict[str, np.ndarray]:
    r"""Linear modes of the 6-DOF model and how much each moves the centre distance.

    The undamped modes of ``M phi'' + (K0 + k_mb g g^T) phi = 0`` (mass-normalised). The
    centre distance moves with ``y_g - y_p`` (eq. 4), and what drives it is the mesh force along
    ``g``; the static response of ``y_g - y_p`` to a mesh force ``dN`` is
    ``sum_i (g^T phi_i)(phi_i[y_g] - phi_i[y_p]) / omega_i^2 dN``, and ``share`` is each mode's
    part of that sum in absolute value (normalised to 1). The decay rate
    ``sigma_i = phi_i^T C phi_i / 2`` uses ``C = C0 + q_mb g g^T`` (the modal, uncoupled damping
    approximation).

    Parameters
    ----------
    dyn : geardyn.dynamics.DynamicModel
    k_mb : float, optional
        Mesh stiffness [N/m]; default ``dyn.k_rep`` (mean of the map at the static operating
        point).

    Returns
    -------
    dict
        ``frequency`` [Hz], ``share`` [-], ``decay_rate`` [1/s] of the elastic modes (the rigid
        rotation is left out), ascending in frequency, and ``index``: the *centre-distance
        mode*, the lowest mode with ``share >= 0.1`` (for the paper's pair the bearing mode in
        which the gear centres move against each other).
    """
    from scipy.linalg import eigh

    k = dyn.k_rep if k_mb is None else float(k_mb)
    K = dyn.K0 + k * np.outer(dyn.g, dyn.g)
    C = dyn.C0 + dyn.q_mb * np.outer(dyn.g, dyn.g)
    lam, phi = eigh(K, dyn.M)
    elastic = lam > 1e-9 * lam.max()
    lam, phi = lam[elastic], phi[:, elastic]
    contrib = np.abs((dyn.g @ phi) * (phi[3] - phi[1])) / lam
    share = contrib / contrib.sum()
    sigma = 0.5 * np.einsum("ij,ik,kj->j", phi, C, phi)
    idx = int(np.nonzero(share >= 0.1)[0][0])
    return {"frequency": np.sqrt(lam) / (2 * np.pi), "share": share, "decay_rate": sigma,
            "index": idx}


def run_times(case, dyn) -> tuple[float, float]:
    """Settling and recorded times [s] of a point (module docstring), for ``dyn`` built from
    ``case``; the settling time is rounded up to whole time steps."""
    modes = centre_distance_modes(dyn)
    sigma = float(modes["decay_rate"][modes["index"]])
    settle = max(float(case.simulation.settle_time), 3.0 / sigma if sigma > 0 else math.inf)
    dt = float(case.simulation.dt)
    settle = math.ceil(settle / dt - 1e-9) * dt  # whole steps: refined runs record alike
    rev = 2 * math.pi / float(dyn.speed)
    n_rev = max(2, math.ceil(float(case.simulation.record_time) / rev - 1e-9))
    return settle, n_rev * rev


def timed_case(case, stiffness_map):
    """``case`` with the study's settle and record times and the predictor evaluation, and the
    centre-distance mode's frequency [Hz] and decay rate [1/s]."""
    from ..dynamics import DynamicModel

    dyn = DynamicModel.from_case(case, stiffness_map)
    modes = centre_distance_modes(dyn)
    settle, record = run_times(case, dyn)
    c = case.with_overrides({"simulation.settle_time": settle, "simulation.record_time": record,
                             "simulation.stiffness_evaluation": "predictor"},
                            source="model-II study")
    i = modes["index"]
    return c, float(modes["frequency"][i]), float(modes["decay_rate"][i])


# ============================================================================================
# one point
# ============================================================================================
def _status_of(exc: Exception) -> int:
    from ..dynamics._kernel import STATUS_TEXT

    text = str(exc)
    for code, msg in STATUS_TEXT.items():
        if msg in text:
            return int(code)
    return 9


def _ratio(ref: np.ndarray, other: np.ndarray) -> float:
    """``RMS(ref - other) / STD(ref)`` (NaN for a constant ``ref``)."""
    std = float(np.std(ref))
    d = float(np.sqrt(np.mean((ref - other) ** 2)))
    return d / std if std > 0 else (0.0 if d == 0 else math.nan)


def _iterations(ds) -> tuple[float, float, float, float]:
    it = np.asarray(ds["iterations"].values, dtype=float)
    return (float(np.mean(it > 0)), float(np.mean(it)), float(it.max()),
            float(ds.attrs.get("steps_without_fixed_point", 0)))


def compare_point(case, stiffness_map, *, start_evaluation: bool = True,
                  signals: Sequence[str] = SIGNALS) -> dict[str, float]:
    r"""Model II and model I-static (and model II with start-of-step evaluation) at one point.

    Parameters
    ----------
    case : Case
        The point's case (:func:`point_case`); its ``stiffness_evaluation`` is used for the
        model II / I-static pair (the study sets ``"predictor"``).
    stiffness_map : StiffnessMap
        The map both models use.
    start_evaluation : bool
        Also run model II with ``stiffness_evaluation = "start"`` (the paper's Fig. 7).
    signals : sequence of str
        Record variables compared.

    Returns
    -------
    dict
        Floats (NaN where a run failed or was not run):

        * ``status_ii``, ``status_i_static``, ``status_ii_start``: :data:`STATUS_NAMES` codes;
        * ``ratio__<signal>``: ``RMS(II - I-static) / STD(II)`` [-];
        * ``start_ratio__<signal>``: ``RMS(II - II_start) / STD(II)`` [-];
        * ``iterating_fraction``, ``mean_iterations``, ``max_iterations``,
          ``steps_without_fixed_point`` of model II (recorded steps), and the same with a
          ``start_`` prefix for the start-of-step run;
        * ``static_centre_distance_change`` [m]; ``centre_distance_std``,
          ``centre_distance_min``, ``centre_distance_max`` of model II [m];
        * ``separation_fraction`` of model II [-];
        * ``settle_time``, ``record_time`` [s] (as run); ``seconds`` [s] wall time.
    """
    from ..dynamics import DynamicModel, simulate, static_equilibrium

    t0 = time.perf_counter()
    out: dict[str, float] = {f"status_{r}": float(NOT_RUN) for r in _RUNS}
    nan = math.nan
    for s in signals:
        out[f"ratio__{s}"] = nan
        out[f"start_ratio__{s}"] = nan
    for p in ("", "start_"):
        for n in ("iterating_fraction", "mean_iterations", "max_iterations",
                  "steps_without_fixed_point"):
            out[p + n] = nan
    for n in ("centre_distance_std", "centre_distance_min", "centre_distance_max",
              "separation_fraction"):
        out[n] = nan
    out["settle_time"] = float(case.simulation.settle_time)
    out["record_time"] = float(case.simulation.record_time)
    dyn = DynamicModel.from_case(case, stiffness_map)
    static = static_equilibrium(dyn, stiffness_map, which="I")  # no map-range check
    out["static_centre_distance_change"] = float(static.centre_distance_change)
    if not stiffness_map.covers(static.centre_distance_change):
        out["seconds"] = time.perf_counter() - t0
        return out
    records = {}
    runs = [("ii", "II", None), ("i_static", "I-static", None)]
    if start_evaluation:
        runs.append(("ii_start", "II", "start"))
    for key, model, ev in runs:
        c = case if ev is None else case.with_overrides(
            {"simulation.stiffness_evaluation": ev}, source="model-II study")
        try:
            records[key] = simulate(c, stiffness_map, model=model)
            out[f"status_{key}"] = 0.0
        except NumericalError as exc:
            out[f"status_{key}"] = float(_status_of(exc))
        except GeardynError:
            out[f"status_{key}"] = 9.0
    ii = records.get("ii")
    if ii is not None:
        (out["iterating_fraction"], out["mean_iterations"], out["max_iterations"],
         out["steps_without_fixed_point"]) = _iterations(ii)
        dd = np.asarray(ii["centre_distance_change"].values, dtype=float)
        out["centre_distance_std"] = float(np.std(dd))
        out["centre_distance_min"], out["centre_distance_max"] = float(dd.min()), float(dd.max())
        out["separation_fraction"] = float(1.0 - np.mean(ii["contact"].values))
        for other, prefix in (("i_static", "ratio__"), ("ii_start", "start_ratio__")):
            rec = records.get(other)
            if rec is None:
                continue
            for s in signals:
                out[prefix + s] = _ratio(np.asarray(ii[s].values, dtype=float),
                                         np.asarray(rec[s].values, dtype=float))
    st = records.get("ii_start")
    if st is not None:
        (out["start_iterating_fraction"], out["start_mean_iterations"],
         out["start_max_iterations"], out["start_steps_without_fixed_point"]) = _iterations(st)
    out["seconds"] = time.perf_counter() - t0
    return out


# ============================================================================================
# time-step convergence of the evaluation schemes at one point
# ============================================================================================
def evaluation_convergence(case, stiffness_map, refinements: Sequence[int] = (1, 2, 4, 8),
                           signals: Sequence[str] = MAIN_SIGNALS):
    r"""How far the predictor and the start-of-step evaluations are from the converged model II,
    and whether the model II / I-static ratio is converged in the time step, at one point.

    The point's case is run with ``dt / r`` and decimation ``r`` for each refinement ``r`` (the
    same recorded instants): model II with the predictor and with the start-of-step evaluation,
    and model I-static. The reference is model II with the predictor at the finest step. This is
    a second method (time-step refinement), not a value echoed from the grid.

    Parameters
    ----------
    case : Case
        The point's case (with its settle and record times).
    stiffness_map : StiffnessMap
    refinements : sequence of int
        Step divisors, increasing (default 1, 2, 4, 8).
    signals : sequence of str

    Returns
    -------
    xarray.Dataset
        Dimensions ``dt`` [s] and ``signal`` (labels, units "1"): ``error_predictor``,
        ``error_start`` (``RMS(II_ref - II) / STD(II_ref)``) and ``rms_ii_minus_i_static`` at
        each step [-].

    Raises
    ------
    NumericalError
        A run fails (the caller records it).
    """
    import xarray as xr

    from ..dynamics import simulate

    refinements = [int(r) for r in refinements]
    if not refinements or any(r < 1 for r in refinements) or refinements != sorted(
            set(refinements)):
        raise InputError("refinements", refinements, "increasing whole numbers >= 1")
    dt0 = float(case.simulation.dt)
    dec0 = int(case.simulation.decimation)
    # the settling time in whole steps of dt0, so every refinement records the same instants
    settle = round(float(case.simulation.settle_time) / dt0) * dt0
    recs = {}
    for r in refinements:
        c = case.with_overrides({"simulation.dt": dt0 / r, "simulation.decimation": dec0 * r,
                                 "simulation.settle_time": settle}, source="model-II study")
        for key, model, ev in (("pred", "II", "predictor"), ("start", "II", "start"),
                               ("static", "I-static", "predictor")):
            cc = c.with_overrides({"simulation.stiffness_evaluation": ev},
                                  source="model-II study")
            recs[(r, key)] = simulate(cc, stiffness_map, model=model)
    ref = recs[(refinements[-1], "pred")]
    n = min(rec.sizes["time"] for rec in recs.values())
    t_ref = np.asarray(ref["time"].values[:n], dtype=float)
    for rec in recs.values():
        if not np.allclose(np.asarray(rec["time"].values[:n], dtype=float), t_ref, rtol=0.0,
                           atol=1e-6 * dt0):
            raise NumericalError("the refined runs do not record the same instants")
    shape = (len(refinements), len(signals))
    e_pred, e_start, ratio = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    for i, r in enumerate(refinements):
        for j, s in enumerate(signals):
            x = np.asarray(ref[s].values[:n], dtype=float)
            p = np.asarray(recs[(r, "pred")][s].values[:n], dtype=float)
            e_pred[i, j] = _ratio(x, p)
            e_start[i, j] = _ratio(x, np.asarray(recs[(r, "start")][s].values[:n], dtype=float))
            ratio[i, j] = _ratio(p, np.asarray(recs[(r, "static")][s].values[:n], dtype=float))
    dims = ("dt", "signal")
    return xr.Dataset(
        {"error_predictor": (dims, e_pred, {"units": "1", "long_name": "RMS(II reference - II "
                                            "predictor) / STD(II reference)"}),
         "error_start": (dims, e_start, {"units": "1", "long_name": "RMS(II reference - II "
                                         "start-of-step) / STD(II reference)"}),
         "rms_ii_minus_i_static": (dims, ratio, {"units": "1", "long_name": "RMS(II predictor "
                                                 "- I-static) / STD(II predictor) at this step"})},
        coords={"dt": ("dt", dt0 / np.asarray(refinements, float), {"units": "s",
                                                                     "long_name": "time step"}),
                "signal": ("signal", list(signals), {"units": "1",
                                                     "long_name": "compared record variable"})},
        attrs={"reference": f"model II, predictor evaluation, dt = {dt0 / refinements[-1]:.6g} s",
               "recorded_samples": int(n)})

# ============================================================================================
# the sweep
# ============================================================================================
class ModelRegimeEvaluator(Evaluator):
    """What a run of the study's sweep computes: :func:`compare_point` at the study's times.

    Outputs (per run, float64): the scalars of :func:`compare_point` (``status_*``, iteration
    counts, centre-distance statistics [m], ``settle_time``, ``record_time``, ``seconds`` [s]),
    ``ratio__<signal>`` and ``start_ratio__<signal>`` for every signal of :data:`SIGNALS` [-],
    ``ratio_max`` (largest ``ratio__`` over :data:`MAIN_SIGNALS`) [-], ``mode_frequency`` [Hz]
    and ``mode_decay_rate`` [1/s] of the centre-distance mode. The stiffness map comes from the
    sweep's per-process memo over :func:`geardyn.stiffness.build_map` (disk cache).

    Parameters
    ----------
    start_evaluation : bool
        Also run model II with the start-of-step evaluation (paper Fig. 7).
    """

    def __init__(self, start_evaluation: bool = True):
        self.start_evaluation = bool(start_evaluation)

    def outputs(self, case, pilot: Mapping[str, Any] | None = None) -> list[Output]:
        outs = [Output(name, units, long) for name, (units, long) in _SCALARS.items()]
        for s in SIGNALS:
            outs.append(Output(f"ratio__{s}", "1", f"RMS(model II - model I-static) / STD(model "
                                                   f"II) of {s}"))
            outs.append(Output(f"start_ratio__{s}", "1", "RMS(model II predictor - model II "
                                                         f"start-of-step) / STD(model II) of {s}"))
        outs.append(Output("ratio_max", "1", "largest RMS(model II - model I-static) / STD(model "
                                             "II) over " + ", ".join(MAIN_SIGNALS)))
        return outs

    def __call__(self, case, seed: int) -> dict[str, Any]:
        from .sweep.evaluate import _stiffness_map  # the sweep's per-process map memo

        smap = _stiffness_map(case)
        c, f_mode, sigma = timed_case(case, smap)
        out = compare_point(c, smap, start_evaluation=self.start_evaluation)
        vals = [out[f"ratio__{s}"] for s in MAIN_SIGNALS]
        fin = [v for v in vals if math.isfinite(v)]
        out["ratio_max"] = max(fin) if fin else math.nan
        out["mode_frequency"], out["mode_decay_rate"] = f_mode, sigma
        return out

    def prepare_key(self, case) -> str | None:
        from ..cache import cache_key
        from ..stiffness import map_inputs

        return cache_key(map_inputs(case, case.stiffness.method, True))

    def prepare(self, case) -> None:
        from .sweep.evaluate import _stiffness_map

        _stiffness_map(case)

    def identity(self) -> dict:
        return {"evaluator": "geardyn.studies.model_regimes.ModelRegimeEvaluator",
                "start_evaluation": self.start_evaluation, "signals": list(SIGNALS),
                "main_signals": list(MAIN_SIGNALS), "rules": RULES}


def load_study_sweep(sweep: str | os.PathLike | None = None, *, quick: bool = False, case=None,
                     overrides: Sequence[str] = (), method: str | None = None,
                     max_runs: int | None = None):
    """The study's sweep: the shipped file (or ``sweep``) with :func:`study_case` applied to its
    base case.

    Parameters
    ----------
    sweep : path-like or str, optional
        A sweep file, or a shipped sweep's name; default :data:`SWEEP` (:data:`QUICK_SWEEP` with
        ``quick``).
    quick : bool
        The coarse shipped grid.
    case : Case, optional
        Replaces the sweep's base case (the sweep's ``[set]`` is applied on top of it).
    overrides : sequence of str
        ``dotted.key=value`` overrides of the base case (the CLI's ``--set``).
    method : {"pem", "fe"}, optional
        Stiffness method; default the sweep's base case's.
    max_runs : int, optional
        The sweep's run-count limit.

    Returns
    -------
    geardyn.studies.sweep.Sweep

    Raises
    ------
    InputError
        An axis other than :data:`AXES`, a bearing axis whose gear counterpart is not linked to
        it, sampled dimensions, or a base case :func:`study_case` refuses.
    """
    import dataclasses

    from .sweep import load_sweep

    name = sweep if sweep is not None else (QUICK_SWEEP if quick else SWEEP)
    sw = load_sweep(name, max_runs=max_runs)
    if sw.dimensions:
        raise InputError("sample", "sampled dimensions", "a grid sweep ([axes] only): the study "
                                                         "maps its axes")
    for a in sw.axes:
        if a.key not in AXES:
            raise InputError(f"axes.{a.key}", a.key, "one of the study's axes: "
                                                     + ", ".join(AXES))
        if a.key in _LINKS and sw.links.get(_LINKS[a.key]) != a.key:
            raise InputError(f"link.{_LINKS[a.key]}", sw.links.get(_LINKS[a.key]),
                             f"{a.key!r}: the study varies both bearings alike")
    base = sw.base_case
    if case is not None:
        base = case.with_overrides(dict(sw.spec.set or {}), source="sweep file [set]") \
            if sw.spec.set else case
    if overrides:
        base = base.with_overrides(list(overrides), source="--set")
    base = study_case(base, method or base.stiffness.method)
    return dataclasses.replace(sw, base_case=base)


def model_regimes(out: str | os.PathLike, *, sweep=None, quick: bool = False, case=None,
                  overrides: Sequence[str] = (), method: str | None = None,
                  workers: int | None = None, scheduler: str | None = None, client=None,
                  force: bool = False, start_evaluation: bool = True, convergence: bool = True,
                  runup: bool = True,
                  progress: Callable[[str, int, int], None] | None = None):
    r"""Run the study's sweep into ``out`` and return model II against model I-static over it.

    The runs go to a local Dask cluster of worker processes (unless ``scheduler`` or
    ``client``): in a script, call this under ``if __name__ == "__main__":``.

    Parameters
    ----------
    out : path-like
        Zarr store of the sweep (created, or resumed: only missing runs are computed).
    sweep, quick, case, overrides, method
        See :func:`load_study_sweep` (default: the shipped full sweep on the paper's case with
        the PEM stiffness).
    workers, scheduler, client, force
        As in :func:`geardyn.studies.sweep.run_sweep`.
    start_evaluation : bool
        Also run model II with the paper's start-of-step evaluation at every point.
    convergence : bool
        Afterwards run :func:`evaluation_convergence` at the point of the largest ``ratio_max``
        (in this process).
    runup : bool
        Also run both models through a run-up across the centre-distance mode
        (:func:`geardyn.studies.model_runup.runup_comparison` on the base case; variables
        ``runup_*`` over ``runup_window``).
    progress : callable, optional
        ``progress(stage, done, total)``: stages ``"simulations"`` (runs, counting those
        already in the store), ``"time-step check"`` and ``"run-up"``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``crack_depth`` [m], ``damping_ratio`` [-], ``bearing_stiffness`` [N/m],
        ``pinion_speed`` [rad/s] (an axis the sweep does not vary has length 1, at the base
        case's value) and ``signal``. Variables: ``rms_ii_minus_i_static`` and
        ``rms_ii_minus_ii_start`` (signal, ...) [-]; ``ratio_max`` [-]; the per-run scalars of
        :class:`ModelRegimeEvaluator` (the status variables are int8, a run the sweep recorded
        as failed is 9); ``mode_frequency`` [Hz] and ``mode_decay_rate`` [1/s]; coordinate
        ``mesh_frequency`` (pinion_speed) [Hz]; ``error`` (message of a failed run) [-]; with
        ``convergence``, ``convergence_*`` (dimensions ``convergence_dt`` [s],
        ``convergence_signal``); with ``runup``, ``runup_*`` (dimensions ``runup_window`` [-],
        ``runup_signal``). Every variable and coordinate has ``units`` ("1" for dimensionless
        numbers and labels) and ``long_name``. Attributes: threshold, map range, torque, dt,
        tolerance, the sweep's text and run statistics, the case (TOML), the version, the run
        time.
    """
    from .._optional import require_extra

    require_extra("sweep")
    from ..config import case_to_toml
    from .sweep import open_sweep, run_sweep

    t0 = time.perf_counter()
    sw = load_study_sweep(sweep, quick=quick, case=case, overrides=overrides, method=method)
    res = run_sweep(sw, out, scheduler=scheduler, workers=workers, client=client, force=force,
                    evaluate=ModelRegimeEvaluator(start_evaluation),
                    progress=(lambda d, n: progress("simulations", d, n)) if progress else None)
    raw = open_sweep(out, unstack=True)
    ds = _result(raw, sw)
    base = sw.base_case
    ds.attrs.update({
        "title": "geardyn model II study: where the centre-distance dynamics matter",
        "threshold": THRESHOLD, "main_signals": ", ".join(MAIN_SIGNALS),
        "stiffness_method": str(base.stiffness.method),
        "map_centre_distance_range": f"{base.stiffness.centre_distance_min:.6g} .. "
                                     f"{base.stiffness.centre_distance_max:.6g} m",
        "input_torque": float(base.motor.torque) if base.motor.law == "constant" else math.nan,
        "input_torque_units": "N m", "dt": float(base.simulation.dt), "dt_units": "s",
        "tolerance": float(base.simulation.tolerance), "tolerance_units": "m",
        "start_evaluation": int(bool(start_evaluation)),
        "rules": RULES,
        "sweep_store": str(res.out), "sweep_text": sw.text, "sweep_origin": str(sw.origin),
        "sweep_runs": int(res.n_runs), "sweep_computed_now": int(res.computed),
        "sweep_resumed": int(bool(res.resumed)), "sweep_failed": int(res.failed),
        "sweep_pending": int(res.pending), "workers": int(res.workers),
        "sweep_seconds": float(res.seconds),
        "case_toml": case_to_toml(base),
        "geardyn_version": str(raw.attrs.get("geardyn_version", "")),
        "citations": "Xue & Howard 2018, Mech. Syst. Signal Process. (models I and II, eq. 4, "
                     "Fig. 7)",
    })
    if convergence:
        ds = _with_convergence(ds, base, progress)
    if runup:
        ds = _with_runup(ds, base, progress)
    ds.attrs["run_seconds"] = float(time.perf_counter() - t0)
    return ds


def _result(raw, sw):
    """The unstacked sweep store as the study's Dataset (dimensions renamed, per-signal ratios
    stacked, absent axes added at the base case's value)."""
    import xarray as xr

    from .sweep import STATUS_FAILED

    base = sw.base_case
    dims = [AXES[k][0] for k in AXES]
    rename = {k: AXES[k][0] for k in AXES if k in raw.dims}
    ds = raw.rename(rename)
    drop = [v for v in ds.variables if v in ("seed", "worker", "warning", "run_seconds")
            or v in sw.links or v.startswith("batch")]
    ds = ds.drop_vars([v for v in drop if v in ds.variables])
    for key, (dim, _, _) in AXES.items():
        if dim not in ds.dims:
            value = float(_dotted(base, key))
            ds = ds.expand_dims({dim: [value]})
    ds = ds.transpose(*dims, ...).load()
    failed = ds["status"].values == STATUS_FAILED
    out = xr.Dataset(coords={d: ds[d] for d in dims})
    for key, (dim, units, long) in AXES.items():
        out[dim].attrs.update({"units": units, "long_name": long, "sweep_key": key})
    for name, (units, long) in _SCALARS.items():
        arr = np.asarray(ds[name].values, dtype=float)
        if name.startswith("status_"):
            arr = np.where(failed | ~np.isfinite(arr), 9, arr).astype(np.int8)
        out[name] = (dims, arr, {"units": units, "long_name": long})
    for prefix, var, long in (
            ("ratio__", "rms_ii_minus_i_static", "RMS(model II - model I-static) / STD(model II)"),
            ("start_ratio__", "rms_ii_minus_ii_start",
             "RMS(model II predictor - model II start-of-step evaluation) / STD(model II)")):
        arr = np.stack([np.asarray(ds[prefix + s].values, dtype=float) for s in SIGNALS])
        out[var] = (("signal", *dims), arr, {"units": "1", "long_name": long})
    out["ratio_max"] = (dims, np.asarray(ds["ratio_max"].values, dtype=float), {
        "units": "1", "long_name": "largest RMS(model II - model I-static) / STD(model II) over "
                                   + ", ".join(MAIN_SIGNALS)})
    out["error"] = (dims, np.asarray(ds["error"].values).astype(str),
                    {"units": "1", "long_name": "message of a run the sweep recorded as failed "
                                                "(empty when it did not fail)"})
    out = out.assign_coords(signal=("signal", list(SIGNALS),
                                    {"units": "1", "long_name": "compared record variable"}))
    w = out["pinion_speed"].values
    out = out.assign_coords(mesh_frequency=("pinion_speed", w * int(base.pinion.teeth)
                                            / (2 * np.pi),
                                            {"units": "Hz",
                                             "long_name": "mesh frequency z1 w / (2 pi)"}))
    return out


def _dotted(case, key: str):
    obj = case
    for part in key.split("."):
        obj = getattr(obj, part)
    return obj


def _with_convergence(ds, base, progress):
    """``ds`` with :func:`evaluation_convergence` at the point of the largest ratio_max."""
    from ..stiffness import build_map

    r = ds["ratio_max"].values
    if not np.any(np.isfinite(r)):
        ds.attrs["convergence_status"] = "not run: no point with both models completed"
        return ds
    if progress is not None:
        progress("time-step check", 0, 1)
    idx = tuple(int(i) for i in np.unravel_index(np.nanargmax(r), r.shape))
    values = [float(ds[AXES[k][0]].values[i]) for k, i in zip(AXES, idx, strict=True)]
    depth, zeta, k, w = values
    case = point_case(base, k, zeta, w, depth)
    smap = build_map(case, cracked=True)
    case, _, _ = timed_case(case, smap)
    ds.attrs["convergence_point"] = (
        f"crack depth {depth:.6g} m, damping ratio {zeta:.6g}, bearing stiffness {k:.6g} N/m, "
        f"pinion speed {w:.6g} rad/s (the largest ratio_max)")
    try:
        conv = evaluation_convergence(case, smap)
    except GeardynError as exc:
        ds.attrs["convergence_status"] = f"failed: {exc}"
        return ds
    finally:
        if progress is not None:
            progress("time-step check", 1, 1)
    ds.attrs["convergence_status"] = "ok"
    ds.attrs["convergence_reference"] = conv.attrs["reference"]
    conv = conv.rename({"dt": "convergence_dt", "signal": "convergence_signal"})
    conv = conv.assign_coords(convergence_signal=(
        "convergence_signal", conv["convergence_signal"].values,
        {"units": "1", "long_name": "record variable compared in the time-step check"}))
    for name in conv.data_vars:
        ds[f"convergence_{name}"] = conv[name]
    return ds


def _with_runup(ds, base, progress):
    """``ds`` with :func:`geardyn.studies.model_runup.runup_comparison` on the base case."""
    from .model_runup import runup_comparison

    cb = (lambda d, n: progress("run-up", d, n)) if progress is not None else None
    if cb is not None:
        cb(0, 2)
    try:
        ru = runup_comparison(base, progress=cb)
    except GeardynError as exc:
        ds.attrs["runup_status"] = f"failed: {exc}"
        return ds
    ds.attrs["runup_status"] = "ok"
    for key, val in ru.attrs.items():
        if key != "title":
            ds.attrs[f"runup_{key}"] = val
    ru = ru.rename({"window": "runup_window", "signal": "runup_signal"})
    ru = ru.assign_coords(
        runup_window=("runup_window", ru["runup_window"].values, {
            "units": "1", "long_name": "index of the run-up window (equal shares of the record, "
                                       "in time order)"}),
        runup_signal=("runup_signal", ru["runup_signal"].values, {
            "units": "1", "long_name": "record variable compared in the run-up"}))
    for name in ru.data_vars:
        ds[f"runup_{name}"] = ru[name]
    return ds
