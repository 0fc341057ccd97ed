r"""Model II against model I-static during a run-up through the centre-distance mode (issue 18,
item 4: "during run-ups").

The steady-speed study (:mod:`geardyn.studies.model_regimes`) finds model II and model
I-static apart only where a mesh harmonic meets the linear mode that moves the centre distance.
A run-up crosses that resonance in a transient; this module runs both models through it:

* the study's base case (:func:`~geardyn.studies.model_regimes.study_case`) with a constant load
  torque (``load.law = "constant"``, balanced at the start speed), so that the mean mesh load and
  the static operating centre distance (model I-static's point) stay those of the case while the
  speed changes;
* a speed-controlled drive (``motor.profile_times`` / ``profile_speeds``, ``drive_gain``) holding
  the start speed through the settling time, then ramping linearly so that the mesh frequency
  sweeps ``ratios`` times the centre-distance mode's frequency; the gain is small, so the drive
  does not clamp the motor and the modes stay those of the steady study;
* both models on the same map, the records cut into ``windows`` equal windows of the ramp, and in
  each window ``RMS(II - I-static) / STD(II)`` of each main signal (each window's mean removed),
  the mean speed, the mesh frequency and the model II iteration counts.

Studies add no physics: this composes :func:`geardyn.dynamics.simulate` and the study case.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["runup_comparison"]


def runup_comparison(base=None, *, ratios: tuple[float, float] = (0.6, 1.5),
                     ramp_time: float = 6.0, windows: int = 60, drive_gain: float = 0.5,
                     signals: Sequence[str] | None = None, stiffness_map=None,
                     progress: Callable[[int, int], None] | None = None):
    r"""Model II and model I-static through a linear run-up across the centre-distance mode.

    Parameters
    ----------
    base : Case, optional
        The study case (default :func:`geardyn.studies.model_regimes.study_case` of the paper's
        case, PEM map).
    ratios : (float, float)
        Mesh frequency over the centre-distance mode's frequency at the start and the end of the
        ramp [-].
    ramp_time : float
        Duration of the ramp [s] (after the case's settling time at the start speed).
    windows : int
        Number of equal windows the ramp's record is cut into.
    drive_gain : float
        Speed-controlled drive: torque per speed error [N m s/rad]. Keep it small against the
        motor inertia times the mode's angular frequency (paper case: 0.0043 kg m^2 x 650 rad/s
        = 2.8 N m s/rad): a stiff drive clamps the motor and moves the resonance (measured on
        the paper case: with 50 N m s/rad the largest difference sits at 0.77 of the undriven
        mode's frequency, with 0.5 at 1.01). With the constant load the speed needs only the
        acceleration torque, so a small gain follows the ramp (lag about 0.2 rad/s).
    signals : sequence of str, optional
        Default :data:`geardyn.studies.model_regimes.MAIN_SIGNALS`.
    stiffness_map : StiffnessMap, optional
        Default: the base case's cracked map.
    progress : callable, optional
        ``progress(done, 2)`` after each model.

    Returns
    -------
    xarray.Dataset
        Dimension ``window``: ``ratio`` (signal, window) [-], ``ratio_max`` [-],
        ``pinion_speed`` [rad/s], ``mesh_frequency`` [Hz], ``frequency_ratio`` (mesh frequency
        over the mode's) [-], ``iterating_steps`` (share of model II's steps with a re-solve)
        [-], ``max_iterations`` [-]; attributes: the mode's frequency [Hz] and decay rate
        [1/s], the speeds, the ramp, the drive gain, the static centre distance change.
    """
    import xarray as xr

    from ..dynamics import DynamicModel, simulate
    from ..stiffness import build_map
    from .model_regimes import MAIN_SIGNALS, centre_distance_modes, run_times, study_case

    base = study_case() if base is None else base
    signals = tuple(MAIN_SIGNALS if signals is None else signals)
    if stiffness_map is None:
        stiffness_map = build_map(base, cracked=True)
    dyn = DynamicModel.from_case(base, stiffness_map)
    modes = centre_distance_modes(dyn)
    f_mode = float(modes["frequency"][modes["index"]])
    z1 = base.pinion.teeth
    w0, w1 = (2 * math.pi * r * f_mode / z1 for r in ratios)
    settle, _ = run_times(base.with_overrides({"load.speed": w0}), dyn)
    case = base.with_overrides({
        "load.law": "constant", "load.speed": w0,
        "motor.profile_times": [settle, settle + ramp_time],
        "motor.profile_speeds": [w0, w1], "motor.drive_gain": drive_gain,
        # no ripple: a fixed-frequency torque does not follow the run-up (refused with a
        # profile); the comparison of II with I-static does not need one
        "motor.ripple": 0.0,
        "simulation.settle_time": settle, "simulation.record_time": ramp_time,
        "simulation.stiffness_evaluation": "predictor"}, source="model-II run-up")
    runs = {}
    for i, which in enumerate(("II", "I-static")):
        runs[which] = simulate(case, stiffness_map, model=which)
        if progress is not None:
            progress(i + 1, 2)
    a, b = runs["II"], runs["I-static"]
    n = a.time.size
    edges = np.linspace(0, n, windows + 1).astype(int)
    ratio = np.full((len(signals), windows), np.nan)
    speed = np.empty(windows)
    iterating = np.empty(windows)
    max_it = np.empty(windows)
    for k in range(windows):
        sl = slice(edges[k], edges[k + 1])
        for s, name in enumerate(signals):
            x = a[name].values[sl]
            y = b[name].values[sl]
            x, y = x - x.mean(), y - y.mean()
            std = float(np.std(x))
            ratio[s, k] = float(np.sqrt(np.mean((x - y) ** 2))) / std if std > 0 else math.nan
        speed[k] = float(np.mean(a["omega_p"].values[sl]))
        it = a["iterations"].values[sl]
        iterating[k] = float(np.mean(it > 0))
        max_it[k] = float(it.max())
    f_mesh = speed * z1 / (2 * math.pi)
    w = ("window",)
    ds = xr.Dataset(
        {"ratio": (("signal",) + w, ratio, {
            "units": "1", "long_name": "RMS(II - I-static) / STD(II) in the window (means "
                                       "removed)"}),
         "ratio_max": (w, np.nanmax(ratio, axis=0), {
             "units": "1", "long_name": "largest ratio over the main signals"}),
         "pinion_speed": (w, speed, {"units": "rad/s", "long_name": "mean pinion speed (model "
                                                                   "II) in the window"}),
         "mesh_frequency": (w, f_mesh, {"units": "Hz", "long_name": "mesh frequency"}),
         "frequency_ratio": (w, f_mesh / f_mode, {
             "units": "1", "long_name": "mesh frequency / centre-distance mode frequency"}),
         "iterating_steps": (w, iterating, {"units": "1", "long_name": "share of model II's "
                                                                       "steps with a re-solve"}),
         "max_iterations": (w, max_it, {"units": "1", "long_name": "most re-solves in a step"})},
        coords={"signal": ("signal", list(signals)), "window": ("window", np.arange(windows))},
        attrs={"title": "model II vs model I-static through a run-up across the centre-distance "
                        "mode",
               "mode_frequency": f_mode, "mode_frequency_units": "Hz",
               "mode_decay_rate": float(modes["decay_rate"][modes["index"]]),
               "mode_decay_rate_units": "1/s",
               "start_speed": w0, "end_speed": w1, "speed_units": "rad/s",
               "ramp_time": float(ramp_time), "ramp_time_units": "s",
               "settle_time": float(settle), "settle_time_units": "s",
               "drive_gain": float(drive_gain), "drive_gain_units": "N m s/rad",
               "load": "constant torque balanced at the start speed (mean mesh load and static "
                       "centre distance those of the case)",
               "static_centre_distance_change": float(a.attrs["static_centre_distance_change"]),
               "static_centre_distance_change_units": "m",
               "dt": float(case.simulation.dt), "dt_units": "s"})
    return ds
