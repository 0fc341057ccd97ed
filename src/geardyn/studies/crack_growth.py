r"""Crack growth prognostics: a root crack grown by LEFM, then the vibration indicators of the
gear pair at a handful of crack lengths, so a user sees each indicator against load cycles.

What it composes (no physics of its own):

1. :func:`geardyn.faults.tooth_growth.grow_case_crack`: the crack path on the cracked tooth
   (plane FE, interaction-integral ``K_I``/``K_II``, maximum tangential stress direction), the
   Paris-law cycles and the FE load-point compliance per crack length.
2. At ``points`` crack lengths along the path (evenly spread over its analysed tips, the initial
   crack and the last tip included), the PEM mesh stiffness map of the **equivalent straight
   crack** (or the FE map of the grown path, below), :func:`geardyn.dynamics.simulate` of
   the case's model on it, and the condition metrics of
   :func:`geardyn.studies.sweep.evaluate.diagnostic_features` (TSA against the cracked gear's
   exact angle, residual, demodulation, FM0/FM4/M6A/M8A/NA4/NB4/energy ratio)
   for each signal; and the same for the healthy pair (no faults) as the baseline.
3. NA4 and NB4 over the run (``NA4_run``, ``NB4_run``): the records of a crack growing in one
   gearbox are the "run" for which Zakrajsek (1993) defined NA4, so each sample's fourth moment
   is divided by the mean variance of every record up to it, the healthy record first
   (:func:`geardyn.diagnostics.metrics.na4` with ``history``):

   .. math:: NA4_{run}(M) = \frac{m_4(r_M)}{\Bigl(\frac1M \sum_{i=1}^{M} m_2(r_i)\Bigr)^2}

   with :math:`r_1` the healthy residual and :math:`r_2 .. r_M` the sampled cracks' in order of
   growth (a sample whose simulation failed is left out of the history); NB4 the same on the
   envelope of the band about the first mesh harmonic. The single-record ``NA4`` (M = 1) is the
   residual's own kurtosis, so it cannot show what NA4 was made for: a residual whose variance
   grows with the damage, which the run's average lags behind. ``residual_variance`` is each
   record's :math:`m_2(r)`.

The equivalent straight crack (an approximation, stated in the output)
-----------------------------------------------------------------------
The PEM models a straight root crack only (:mod:`geardyn.stiffness.pem.crack`: a depth and an
angle to the centreline, from the 30 deg fillet point). The grown path is curved (it kinks at
the first step and bends through the tooth), so each sampled crack is replaced by the straight
crack of its chord: from the mouth to the current tip, depth ``|tip - mouth|`` and angle
``atan2(d_x, -d_y)`` (:func:`geardyn.faults.tooth_growth.equivalent_crack`). The chord is
shorter than the path and it ignores the path's curvature, so the PEM map neither matches the
FE compliance of the curved crack nor is it checked against it here; the FE compliance per
length (``compliance``) is the consistent stiffness measure of the grown crack. A chord outside
the PEM's domain (angle outside ``(0, pi/2)``, tip beyond the opposite fillet) or a simulation
that fails (a nearly broken tooth can separate and run away) leaves that sample's indicators
NaN with the reason in ``simulation_status``.

The FE map of the grown path (``stiffness="fe"``, ``geardyn crack-growth --stiffness fe``)
---------------------------------------------------------------------------------------
Instead of the chord, the FE mesh stiffness of the path itself: the crack is meshed along its
polyline from the mouth through every tip up to the sample
(:class:`geardyn.stiffness.fe.mesh.CrackGeometry` with ``path``,
:func:`geardyn.faults.tooth_growth.crack_at`), one whole FE body per sample (cached). The first
sample, the initial straight crack, gives the straight crack's FE map to round-off
(``tests/fe/test_crack_path_map.py``).

The simulated records are short when the caller asks (``settle_time``, ``record_time``). White
Gaussian noise at ``noise_snr_db`` (default 20 dB, as in the shipped sweep) is added to each
signal before the TSA, drawn from ``numpy.random.default_rng(seed + i)`` for sample ``i``
(the healthy baseline is ``i = 0``): a healthy gear's noise-free TSA difference signal is
numerical residue whose kurtosis means nothing, so without noise (``noise_snr_db=None``) the
healthy baseline of FM4-type metrics is not the ~3 of a measured healthy gear.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import GeardynError, InputError

__all__ = ["METRICS", "RUN_METRICS", "DEFAULT_SIGNALS", "EQUIVALENT_CRACK_NOTE", "sample_indices",
           "add_indicators", "crack_growth_study"]

#: Condition metrics stored per signal: name -> long name.
METRICS = {
    "FM0": "FM0: peak-to-peak of the TSA / sum of mesh harmonic amplitudes",
    "FM4": "FM4: kurtosis of the difference signal",
    "M6A": "M6A: sixth normalised moment of the difference signal",
    "M8A": "M8A: eighth normalised moment of the difference signal",
    "NA4": "NA4 of the residual (single record)",
    "NB4": "NB4 of the envelope (single record)",
    "EnergyRatio": "energy ratio RMS(difference)/RMS(regular)",
    "residual_kurtosis": "kurtosis of the residual signal",
}
#: Metrics over the run (the healthy record, then the samples in order of growth): name ->
#: long name (module docstring, item 3).
RUN_METRICS = {
    "NA4_run": "NA4 over the run: m4 of this record's residual / (mean residual variance of "
               "the healthy record and the samples up to this one)^2 (Zakrajsek 1993)",
    "NB4_run": "NB4 over the run: NA4_run of the envelope of the band about the first mesh "
               "harmonic",
}
#: Simulated signals reduced to indicators (the sweep's defaults).
DEFAULT_SIGNALS = ("v_yg", "omega_p", "transmission_error")

EQUIVALENT_CRACK_NOTE = (
    "indicators use the PEM mesh stiffness of the equivalent straight crack: the chord from the "
    "crack mouth to the current tip (depth |tip - mouth|, angle to the tooth centreline), not "
    "the curved grown path; the FE load-point compliance (variable compliance) is the grown "
    "crack's own stiffness measure")


def sample_indices(n: int, points: int) -> np.ndarray:
    """Indices of ``points`` crack lengths spread evenly over ``n`` analysed tips (first and last
    included; fewer if ``n < points``)."""
    if isinstance(points, bool) or int(points) != points or points < 1:
        raise InputError("points", points, "an integer >= 1 (crack lengths simulated)")
    if n < 1:
        raise InputError("growth", n, "a grown path with at least one analysed tip")
    return np.unique(np.round(np.linspace(0, n - 1, min(int(points), n))).astype(int))


def _features(case, smap, signals, shaft: str, teeth: int, noise_snr_db: float | None = None,
              seed: int = 0) -> dict:
    from ..dynamics import simulate
    from .sweep.evaluate import diagnostic_features

    ds = simulate(case, smap)
    missing = [s for s in (*signals, shaft) if s not in ds.variables]
    if missing:
        raise InputError("signals", missing, "variables of the simulation result: "
                         + ", ".join(sorted(ds.data_vars)))
    d = case.diagnostics
    sig = {s: np.asarray(ds[s].values, dtype=np.float64) for s in signals}
    if noise_snr_db is not None:
        rng = np.random.default_rng(seed)
        scale = 10.0 ** (-float(noise_snr_db) / 20.0)
        sig = {k: v + rng.standard_normal(v.shape) * (np.std(v) * scale) for k, v in sig.items()}
    out = diagnostic_features(sig, np.asarray(ds[shaft].values, dtype=np.float64), teeth=teeth,
                              samples_per_rev=d.samples_per_rev, harmonic=d.harmonic,
                              bandwidth=d.bandwidth, residual_preset=d.residual_preset,
                              keep_tsa=True)
    for s in signals:
        out[f"{s}__units"] = str(ds[s].attrs.get("units", ""))
    return out


def _squared_unit(unit: str) -> str:
    """The unit of a variance of a signal in ``unit``: ``"m/s"`` -> ``"(m/s)^2"``, ``"m"`` ->
    ``"m^2"``, ``""`` or ``"1"`` -> ``"1"``."""
    unit = unit.strip()
    if unit in ("", "1"):
        return "1"
    return f"{unit}^2" if unit.isalnum() else f"({unit})^2"


def _run_metrics(case, tsas: list, teeth: int) -> dict[str, np.ndarray]:
    """NA4 and NB4 over the run, and each record's residual variance (module docstring, item
    3), from the TSAs of one signal: ``tsas[0]`` the healthy record's, then the samples' in
    order of growth (None for a failed sample: NaN, and left out of the history).

    Returns arrays over the records (healthy first): ``NA4_run``, ``NB4_run`` [-] and
    ``residual_variance`` (the signal's unit squared).
    """
    from ..diagnostics.metrics import band_envelope, central_moment, na4
    from ..diagnostics.spectra import residual

    preset = case.diagnostics.residual_preset
    out = {k: np.full(len(tsas), np.nan) for k in (*RUN_METRICS, "residual_variance")}
    res_hist: list[np.ndarray] = []
    env_hist: list[np.ndarray] = []
    for j, x in enumerate(tsas):
        if x is None:
            continue
        r = residual(x, teeth=teeth, preset=preset)
        env = band_envelope(x, teeth=teeth)  # harmonic 1, band (Z-1)//2: as in NB4 itself
        out["residual_variance"][j] = central_moment(r, 2)
        out["NA4_run"][j] = na4(r, res_hist)
        out["NB4_run"][j] = na4(env, env_hist)
        res_hist.append(r)
        env_hist.append(env)
    return out


def add_indicators(case, growth, *, points: int = 5, settle_time: float | None = None,
                   record_time: float | None = None, signals: Sequence[str] = DEFAULT_SIGNALS,
                   n_angle: int = 4096, noise_snr_db: float | None = 20.0, seed: int = 0,
                   progress: Callable[[int, int], None] | None = None,
                   stiffness: str = "pem"):
    """Indicators against cycles at ``points`` crack lengths of a grown path (module docstring).

    Parameters
    ----------
    case : geardyn.config.Case
        The case the path was grown for (its crack, gears, dynamics and diagnostics settings);
        the maps use the PEM whatever ``stiffness.method`` says.
    growth : xarray.Dataset
        From :func:`geardyn.faults.tooth_growth.grow_case_crack`.
    points : int
        Crack lengths simulated.
    settle_time, record_time : float, optional
        Simulation settle and record times [s] (default: the case's).
    signals : sequence of str
        Simulated signals reduced to indicators.
    n_angle : int
        Angles per map period in ``mesh_stiffness``.
    noise_snr_db : float or None
        Signal-to-noise ratio of the white noise added to each signal [dB] (None: none).
    seed : int
        Seed of the noise (sample ``i`` uses ``seed + i``).
    progress : callable, optional
        ``progress(done, total)`` per simulation (healthy first).
    stiffness : {"pem", "fe"}
        ``"pem"``: the PEM map of the equivalent straight crack (module docstring); ``"fe"``:
        the FE map of the grown path itself (the crack meshed as the polyline from the mouth
        through every tip up to the sample, :func:`geardyn.faults.tooth_growth.crack_at`; one
        FE body per sample, cached).

    Returns
    -------
    xarray.Dataset
        ``growth`` plus, over ``sample_length`` [m] (the sampled crack lengths):
        ``sample_cycles`` [-], ``equivalent_depth`` [m], ``equivalent_angle`` [rad],
        ``simulation_status`` (``"ok"`` or the reason of a NaN sample), ``<signal>__<metric>``
        [-] for the metrics of :data:`METRICS` and :data:`RUN_METRICS`,
        ``<signal>__residual_variance`` (the signal's unit squared), ``mesh_stiffness`` [N/m]
        along ``angle`` (the
        PEM map at the design centre distance over its period); the healthy baseline as
        ``<signal>__<metric>_healthy`` and ``healthy_mesh_stiffness``.
    """
    import xarray as xr

    from ..faults.tooth_growth import case_crack, crack_at, equivalent_crack
    from ..stiffness import build_map

    c = case_crack(case)
    if stiffness not in ("pem", "fe"):
        raise InputError("stiffness", stiffness, "'pem' or 'fe'")
    n = growth.sizes["crack_length"]
    idx = sample_indices(n, points)
    over: dict[str, object] = {"stiffness.method": stiffness}
    if settle_time is not None:
        over["simulation.settle_time"] = float(settle_time)
    if record_time is not None:
        over["simulation.record_time"] = float(record_time)
    base = case.with_overrides(over)
    shaft, teeth = (("theta_p", base.pinion.teeth) if c.gear == "pinion"
                    else ("theta_g", base.gear.teeth))
    signals = tuple(signals)
    total = idx.size + 1
    healthy_map = build_map(base, cracked=False)
    if noise_snr_db is not None and not math.isfinite(float(noise_snr_db)):
        raise InputError("noise_snr_db", noise_snr_db, "a finite signal-to-noise ratio in dB, or "
                                                       "None for no noise")
    healthy = _features(base, healthy_map, signals, shaft, teeth, noise_snr_db, seed)
    tsas = {s: [healthy[f"{s}__tsa"]] for s in signals}  # the run: healthy, then the samples
    if progress is not None:
        progress(1, total)
    mouth = (float(growth["path_x"].values[0]), float(growth["path_y"].values[0]))
    lengths = growth["crack_length"].values[idx]
    depth = np.full(idx.size, np.nan)
    angle = np.full(idx.size, np.nan)
    status: list[str] = []
    values = {f"{s}__{m}": np.full(idx.size, np.nan) for s in signals for m in METRICS}
    k_rows: list[np.ndarray | None] = []
    period = None
    for j, k in enumerate(idx):
        tip = (float(growth["tip_x"].values[k]), float(growth["tip_y"].values[k]))
        q, v = equivalent_crack(mouth, tip)
        depth[j], angle[j] = q, v
        row = None
        try:
            if stiffness == "fe":  # the grown path itself, meshed
                cs = base
                smap = _fe_path_map(base, crack_at(growth, int(k), c.depth, c.angle))
            else:
                if not 0 < v < math.pi / 2:
                    raise InputError(f"{c.field}.angle", v, "an equivalent crack angle in (0, "
                                     "pi/2) rad (the chord leaves the PEM's domain)")
                cs = base.with_overrides({f"{c.key}.depth": q, f"{c.key}.angle": v})
                smap = build_map(cs, cracked=True)
            period = smap.period
            th = np.linspace(0.0, period, n_angle, endpoint=False)
            row = np.asarray(smap(th, 0.0), float)
            f = _features(cs, smap, signals, shaft, teeth, noise_snr_db, seed + j + 1)
            for key in values:
                values[key][j] = float(f[key])
            for s in signals:
                tsas[s].append(f[f"{s}__tsa"])
            status.append("ok")
        except GeardynError as exc:
            status.append(" ".join(str(exc).split())[:300])
            for s in signals:
                if len(tsas[s]) < j + 2:
                    tsas[s].append(None)
        k_rows.append(row)
        if progress is not None:
            progress(j + 2, total)
    if period is None:
        period = healthy_map.period
    th = np.linspace(0.0, period, n_angle, endpoint=False)
    kmat = np.stack([r if r is not None else np.full(n_angle, np.nan) for r in k_rows])
    S = "sample_length"
    cyc = growth["cycles"].values[idx]
    data = {
        "sample_cycles": (S, np.asarray(cyc, float),
                          {"units": "1", "long_name": "load cycles from the initial crack at the "
                                                      "sampled length"}),
        "equivalent_depth": (S, depth, {"units": "m", "long_name": "length of the equivalent "
                                        "straight crack (chord from the mouth to the tip)"}),
        "equivalent_angle": (S, angle, {"units": "rad", "long_name": "angle of the equivalent "
                                        "straight crack to the tooth centreline"}),
        "simulation_status": (S, np.array(status, dtype=object),
                              {"long_name": "'ok', or why the sample's indicators are NaN"}),
        "mesh_stiffness": ((S, "angle"), kmat,
                           {"units": "N/m", "long_name": (
                               "PEM mesh stiffness of the equivalent crack" if stiffness == "pem"
                               else "FE mesh stiffness of the grown crack path")
                            + " at the design centre distance"}),
        "healthy_mesh_stiffness": ("angle", np.asarray(healthy_map(th, 0.0), float),
                                   {"units": "N/m", "long_name": f"{stiffness.upper()} mesh "
                                    "stiffness of the healthy pair (no faults)"}),
    }
    for s in signals:
        for m, long in METRICS.items():
            data[f"{s}__{m}"] = (S, values[f"{s}__{m}"], {"units": "1",
                                                         "long_name": f"{long} of {s}"})
            data[f"{s}__{m}_healthy"] = ((), float(healthy[f"{s}__{m}"]), {
                "units": "1", "long_name": f"{long} of {s}, healthy pair (no faults)"})
        run = _run_metrics(base, tsas[s], teeth)
        unit = _squared_unit(healthy[f"{s}__units"])
        for m, long in {**RUN_METRICS, "residual_variance": "variance m2 of the residual"
                        }.items():
            u = unit if m == "residual_variance" else "1"
            data[f"{s}__{m}"] = (S, run[m][1:], {"units": u, "long_name": f"{long} of {s}"})
            data[f"{s}__{m}_healthy"] = ((), float(run[m][0]), {
                "units": u, "long_name": f"{long} of {s}, healthy pair (no faults: the run's "
                                         "first record)"})
    ind = xr.Dataset(data, coords={
        S: (S, np.asarray(lengths, float), {"units": "m", "long_name": "sampled crack length "
                                                                       "along the path"}),
        "angle": ("angle", th, {"units": "rad", "long_name": "pinion angle over the cracked "
                                                             "map's period"}),
    })
    out = xr.merge([growth, ind], combine_attrs="override")
    sim = base.simulation
    out.attrs.update({
        "equivalent_crack": (EQUIVALENT_CRACK_NOTE if stiffness == "pem" else
                             "not used: the indicators use the FE map of the grown path itself "
                             "(equivalent_depth and equivalent_angle describe its chord only)"),
        "indicator_stiffness": stiffness,
        "indicator_map_centre_distances": int(base.stiffness.centre_distances),
        **({"indicator_fe_mesh_refinement": float(base.stiffness.fe.refinement)}
           if stiffness == "fe" else {}),
        "indicator_model": sim.model,
        "indicator_settle_time_s": float(sim.settle_time),
        "indicator_record_time_s": float(sim.record_time),
        "indicator_dt_s": float(sim.dt),
        "indicator_tsa_shaft": shaft,
        "indicator_tsa_teeth": int(teeth),
        "indicator_signals": ", ".join(signals),
        "indicator_noise": ("none (noise-free simulated signals)" if noise_snr_db is None else
                            f"white Gaussian noise at {float(noise_snr_db):g} dB SNR on each "
                            f"signal, numpy default_rng(seed + sample index), seed {seed}"),
    })
    return out


def _fe_path_map(case, crack):
    """The FE mesh stiffness map of ``case`` with its root crack replaced by ``crack`` (a
    grown path) on the case's centre-distance grid (bodies cached by their crack)."""
    from ..stiffness import centre_distance_grid
    from ..stiffness.fe import fe_map

    return fe_map(case, centre_distance_grid(case), cracked=True, crack=crack)


def crack_growth_study(case, *, paris_c: float, paris_m: float, paris_threshold: float = 0.0,
                       step: float | None = None, n_steps: int = 60, points: int = 5,
                       settle_time: float | None = None, record_time: float | None = None,
                       signals: Sequence[str] = DEFAULT_SIGNALS,
                       noise_snr_db: float | None = 20.0, seed: int = 0,
                       progress: Callable[..., None] | None = None, stiffness: str = "pem"):
    """Grow the case's crack and compute the indicators against cycles (module docstring).

    Parameters
    ----------
    case : geardyn.config.Case
    paris_c, paris_m, paris_threshold, step, n_steps
        As in :func:`geardyn.faults.tooth_growth.grow_case_crack` (``C`` in
        m/cycle/(Pa m^0.5)^m, ``Delta K_th`` in Pa m^0.5, ``step`` in m).
    points, settle_time, record_time, signals, noise_snr_db, seed, stiffness
        As in :func:`add_indicators`.
    progress : callable, optional
        ``progress(stage, done, total)`` with stages ``"crack growth"`` and ``"indicators"``.

    Returns
    -------
    xarray.Dataset
        See :func:`geardyn.faults.tooth_growth.grow_case_crack` and :func:`add_indicators`.
    """
    from ..faults.tooth_growth import grow_case_crack

    def stage(name):
        if progress is None:
            return None
        return lambda done, total: progress(name, done, total)

    sample_indices(1, points)  # a bad count fails before the FE work
    growth = grow_case_crack(case, paris_c=paris_c, paris_m=paris_m,
                             paris_threshold=paris_threshold, step=step, n_steps=n_steps,
                             progress=stage("crack growth"))
    if progress is not None:  # the growth's total was its largest step count
        n = growth.sizes["crack_length"]
        progress("crack growth", n, n)
    return add_indicators(case, growth, points=points, settle_time=settle_time,
                          record_time=record_time, signals=signals,
                          noise_snr_db=noise_snr_db, seed=seed, progress=stage("indicators"),
                          stiffness=stiffness)
