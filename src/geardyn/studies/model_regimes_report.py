r"""Figures and a short HTML page of the model II study (:mod:`geardyn.studies.model_regimes`).

Reads the study's Dataset (never the reverse): :func:`regime_summary` states from the results
where ``RMS(II - I-static) / STD(II)`` exceeds the 10 % threshold, or that it nowhere does, with
the range explored; :func:`figure_ratio_maps`, :func:`figure_resonance_curves`,
:func:`figure_iterations` and :func:`figure_convergence` draw it; :func:`write_report` writes
``model_regimes.html`` (self-contained, figures embedded) and the PNGs into ``figures/``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["regime_summary", "figure_ratio_maps", "figure_resonance_curves",
           "figure_iterations", "figure_convergence", "write_report"]

_SIGNAL_LABELS = {"transmission_error": "transmission error", "mesh_force": "mesh force",
                  "v_yg": "gear centre velocity v_yg", "omega_p": "pinion speed omega_p",
                  "y_g": "gear centre displacement y_g",
                  "centre_distance_change": "centre distance change",
                  "mesh_stiffness": "mesh stiffness"}


def _mm(x: float) -> str:
    return f"{x * 1e3:g} mm"


def _crack_label(depth: float) -> str:
    return "healthy" if depth == 0 else f"crack {_mm(depth)}"


def _ok(ds) -> np.ndarray:
    """Points where model II and model I-static both completed."""
    return (ds["status_ii"].values == 0) & (ds["status_i_static"].values == 0)


def _mode(ds) -> np.ndarray:
    """Centre-distance mode frequency [Hz] per (bearing stiffness, damping ratio): the median
    over crack depths and speeds of the runs' values (the mode depends on neither but the
    map's mean stiffness, which the crack changes by well under 1 %)."""
    f = np.asarray(ds["mode_frequency"].values, dtype=float)  # (crack, zeta, k, speed)
    f = f.transpose(2, 1, 0, 3).reshape(f.shape[2], f.shape[1], -1)
    out = np.full(f.shape[:2], np.nan)
    for i, j in np.ndindex(out.shape):
        v = f[i, j][np.isfinite(f[i, j])]
        if v.size:
            out[i, j] = float(np.median(v))
    return out


def _point_text(ds, idx) -> str:
    c, z, k, w = idx
    speed = float(ds.pinion_speed.values[w])
    fm = float(ds.mesh_frequency.values[w])
    f0 = float(ds.mode_frequency.values[c, z, k, w])
    return (f"k = {ds.bearing_stiffness.values[k]:.3g} N/m, zeta = "
            f"{100 * ds.damping_ratio.values[z]:g} %, pinion speed {speed:.3g} rad/s (mesh "
            f"{fm:.4g} Hz = {fm / f0:.3g} x the centre-distance mode {f0:.4g} Hz), "
            f"{_crack_label(float(ds.crack_depth.values[c]))}")



def _span(values, fmt: str) -> str:
    """``lo..hi`` of ``values`` in format ``fmt``, or the one value when they are all equal."""
    lo, hi = float(np.min(values)), float(np.max(values))
    return format(lo, fmt) if lo == hi else f"{format(lo, fmt)}..{format(hi, fmt)}"


def _count(values) -> str:
    """``n values`` (``1 value``)."""
    n = int(np.size(values))
    return f"{n} value" + ("" if n == 1 else "s")

def regime_summary(ds) -> dict:
    """The findings of a study Dataset, computed from its values (threshold ``ds.threshold``).

    Returns
    -------
    dict
        ``threshold``; ``points``, ``simulated``, ``compared`` (both models completed),
        ``not_run``, ``failed`` (counts); ``above`` (compared points above the threshold);
        ``max_ratio`` [-] and ``max_point`` (text) and ``max_signal``; ``ranges`` (text of the
        explored ranges); ``by_stiffness`` rows ``(k [N/m], mode [Hz], static centre distance
        change [m], compared, above, max ratio, speeds above [rad/s] as text)``; ``sentence``:
        the headline; ``failures``: ``{status text: (run, count, example point)}``;
        ``iterations``: predictor / start-of-step statistics; ``crack_effect``: the largest
        ``|ratio(crack) - ratio(healthy)|`` [-].
    """
    from .model_regimes import MAIN_SIGNALS, NOT_RUN, STATUS_NAMES

    thr = float(ds.attrs.get("threshold", 0.1))
    r = ds["ratio_max"].values
    ok = _ok(ds) & np.isfinite(r)
    st = ds["status_ii"].values
    not_run = st == NOT_RUN
    out: dict = {"threshold": thr, "points": int(r.size), "not_run": int(not_run.sum()),
                 "simulated": int((~not_run).sum()), "compared": int(ok.sum())}
    out["above"] = int((ok & (r > thr)).sum())
    failures: dict = {}
    for run, var in (("model II", "status_ii"), ("model I-static", "status_i_static"),
                     ("model II start-of-step", "status_ii_start")):
        if var not in ds:
            continue
        s = ds[var].values
        for code in np.unique(s):
            if code in (0, NOT_RUN):
                continue
            where = np.argwhere(s == code)
            failures[f"{run}: {STATUS_NAMES.get(int(code), str(code))}"] = (
                run, int(len(where)), _point_text(ds, tuple(where[0])))
    out["failures"] = failures
    out["failed"] = int(((~not_run) & ~_ok(ds)).sum())
    k = ds.bearing_stiffness.values
    w = ds.pinion_speed.values
    z = 100 * ds.damping_ratio.values
    fm = ds.mesh_frequency.values
    out["ranges"] = (
        f"bearing stiffness {_span(k, '.3g')} N/m ({_count(k)}, both bearings), "
        f"bearing damping ratio {_span(z, 'g')} % ({_count(z)}), pinion "
        f"speed {_span(w, '.3g')} rad/s ({_count(w)}, mesh frequency {_span(fm, '.4g')} Hz), "
        + ", ".join(_crack_label(float(c)) for c in ds.crack_depth.values)
        + f"; input torque {ds.attrs.get('input_torque', math.nan):g} N m, "
          f"{ds.attrs.get('stiffness_method', '')} stiffness")
    if ok.any():
        rr = np.where(ok, r, -np.inf)
        idx = tuple(int(i) for i in np.unravel_index(np.argmax(rr), r.shape))
        out["max_ratio"] = float(r[idx])
        out["max_point"] = _point_text(ds, idx)
        per = ds["rms_ii_minus_i_static"].sel(signal=list(MAIN_SIGNALS)).values[(slice(None),
                                                                                   *idx)]
        out["max_signal"] = MAIN_SIGNALS[int(np.nanargmax(per))]
    else:
        out["max_ratio"], out["max_point"], out["max_signal"] = math.nan, "", ""
    rows = []
    for ik, kv in enumerate(k):
        sel = ok[:, :, ik, :]
        rv = r[:, :, ik, :]
        above_w = sorted({float(w[i]) for i in np.argwhere(sel & (rv > thr))[:, -1]})
        rows.append((float(kv), float(np.nanmax(_mode(ds)[ik])),
                     float(np.nanmax(ds.static_centre_distance_change.values[:, :, ik, :])),
                     int(sel.sum()), int((sel & (rv > thr)).sum()),
                     float(np.max(rv[sel])) if sel.any() else math.nan,
                     ", ".join(f"{x:.3g}" for x in above_w) if above_w else "none"))
    out["by_stiffness"] = rows
    out["by_damping"] = [(float(zv), float(np.max(r[:, iz][ok[:, iz]])) if ok[:, iz].any()
                          else math.nan) for iz, zv in enumerate(ds.damping_ratio.values)]
    # how close to a resonance (mesh frequency or its n-th harmonic = centre-distance mode) the
    # points above the threshold lie: min over n = 1, 2, 3 of |n f_mesh / f_mode - 1|
    above = np.argwhere(ok & (r > thr))
    f0 = _mode(ds)
    detune = []
    for _c, z, kk, ww in above:
        x = float(ds.mesh_frequency.values[ww]) / f0[kk, z]
        detune.append(min((abs(n * x - 1.0), n) for n in (1, 2, 3)))
    out["above_detuning"] = (max(d for d, _ in detune), sorted({n for _, n in detune})) \
        if detune else (math.nan, [])
    k_above = sorted({float(k[i]) for i in above[:, 2]}) if above.size else []
    out["above_stiffness"] = (k_above[0], k_above[-1]) if k_above else (math.nan, math.nan)
    if out["compared"] == 0:
        out["sentence"] = ("No point of the grid ran both models to completion, so the study "
                           f"says nothing about the difference. Range explored: {out['ranges']}.")
    elif out["above"] == 0:
        out["sentence"] = (
            f"Nowhere in the range explored does RMS(II - I-static)/STD(II) exceed "
            f"{100 * thr:g} % in any of the main signals ({', '.join(MAIN_SIGNALS)}): the "
            f"largest is {100 * out['max_ratio']:.3g} % ({out['max_signal']}) at "
            f"{out['max_point']}. Range explored: {out['ranges']}.")
    else:
        out["sentence"] = (
            f"Model II and model I-static differ by more than {100 * thr:g} % (RMS(II - "
            f"I-static)/STD(II), largest over {', '.join(MAIN_SIGNALS)}) at {out['above']} of "
            f"the {out['compared']} points where both ran; the largest difference is "
            f"{100 * out['max_ratio']:.3g} % ({out['max_signal']}) at {out['max_point']}. "
            f"Range explored: {out['ranges']}.")
    it: dict = {}
    for label, pre in (("predictor", ""), ("start-of-step", "start_")):
        f = ds[f"{pre}iterating_fraction"].values
        good = np.isfinite(f)
        it[label] = {"points": int(good.sum()),
                     "points_iterating": int((good & (f > 0)).sum()),
                     "max_fraction": float(np.nanmax(f)) if good.any() else math.nan,
                     "mean_fraction": float(np.nanmean(f)) if good.any() else math.nan,
                     "max_iterations": float(np.nanmax(ds[f"{pre}max_iterations"].values))
                     if good.any() else math.nan,
                     "steps_without_fixed_point": float(np.nansum(
                         ds[f"{pre}steps_without_fixed_point"].values))}
    if "rms_ii_minus_ii_start" in ds:
        d = ds["rms_ii_minus_ii_start"].sel(signal=list(MAIN_SIGNALS)).values
        with np.errstate(all="ignore"):
            dmax = np.nanmax(np.where(np.isnan(d), -np.inf, d), axis=0)
        dmax = np.where(np.isfinite(dmax), dmax, np.nan)
        both = np.isfinite(dmax) & ok
        it["start_vs_predictor"] = {
            "median": float(np.median(dmax[both])) if both.any() else math.nan,
            "max": float(np.max(dmax[both])) if both.any() else math.nan,
            "min": float(np.min(dmax[both])) if both.any() else math.nan,
            "exceeds_model_difference": int((both & (dmax > r)).sum()),
            "points": int(both.sum())}
    out["iterations"] = it
    c = ds.crack_depth.values
    if c.size > 1 and c[0] == 0:
        with np.errstate(invalid="ignore"):
            diff = np.abs(r[1:] - r[:1])
        out["crack_effect"] = float(np.nanmax(diff)) if np.any(np.isfinite(diff)) else math.nan
    else:
        out["crack_effect"] = math.nan
    return out


# ----------------------------------------------------------------------------- figures
def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges of log-spaced centres (geometric midpoints)."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] / 1.5, v[0] * 1.5])
    mid = np.sqrt(v[:-1] * v[1:])
    return np.concatenate([[v[0] ** 2 / mid[0]], mid, [v[-1] ** 2 / mid[-1]]])


def _mode_lines(ax, ds, iz: int, teeth: int) -> None:
    k = ds.bearing_stiffness.values
    f0 = _mode(ds)[:, iz]
    w = ds.pinion_speed.values
    for n, style in ((1, "-"), (2, "--"), (3, ":")):
        ws = 2 * np.pi * f0 / (n * teeth)
        ax.plot(k, ws, style, color="white", lw=1.3, alpha=0.9,
                label=f"{n} x mesh freq. = centre-distance mode" if n > 1 else
                "mesh freq. = centre-distance mode")
    ax.set_ylim(_edges(w)[0], _edges(w)[-1])


def figure_ratio_maps(ds, variable: str = "ratio_max"):
    """Maps of ``variable`` over bearing stiffness and pinion speed: one panel per damping ratio
    (rows) and crack depth (columns), log colour scale, the threshold contour, the speeds at
    which the mesh frequency (or its 2nd, 3rd harmonic) meets the centre-distance mode, points
    not run (grey) and failed (x)."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from .model_regimes import NOT_RUN

    thr = float(ds.attrs.get("threshold", 0.1))
    nz, nc = ds.sizes["damping_ratio"], ds.sizes["crack_depth"]
    fig, axes = plt.subplots(nz, nc, figsize=(4.3 * nc + 1.2, 3.4 * nz + 0.6), squeeze=False,
                             sharex=True, sharey=True, layout="constrained")
    k, w = ds.bearing_stiffness.values, ds.pinion_speed.values
    ke, we = _edges(k), _edges(w)
    data = ds[variable].values
    ok = _ok(ds)
    vals = data[ok & np.isfinite(data)]
    lo = max(float(vals.min()) if vals.size else 1e-4, 1e-4)
    hi = max(float(vals.max()) if vals.size else 1.0, thr * 1.01)
    norm = LogNorm(vmin=min(lo, thr / 10), vmax=hi)
    teeth = int(round(float(ds.mesh_frequency.values[0]) * 2 * np.pi / float(w[0])))
    mesh = None
    for iz in range(nz):
        for ic in range(nc):
            ax = axes[iz, ic]
            z = np.where(ok[ic, iz] & np.isfinite(data[ic, iz]), data[ic, iz], np.nan).T
            ax.set_facecolor("#c8c8c8")
            mesh = ax.pcolormesh(ke, we, np.ma.masked_invalid(z), norm=norm, cmap="viridis",
                                 shading="flat")
            if np.nanmax(z, initial=-np.inf) > thr > np.nanmin(z, initial=np.inf) \
                    and min(z.shape) > 1:
                ax.contour(k, w, np.nan_to_num(z, nan=0.0), levels=[thr], colors="red",
                           linewidths=1.6)
            failed = ~ok[ic, iz] & (ds["status_ii"].values[ic, iz] != NOT_RUN)
            if failed.any():
                ik, iw = np.nonzero(failed)
                ax.plot(k[ik], w[iw], "x", color="red", ms=6, mew=1.5, label="failed run")
            _mode_lines(ax, ds, iz, teeth)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"zeta = {100 * ds.damping_ratio.values[iz]:g} %, "
                         f"{_crack_label(float(ds.crack_depth.values[ic]))}", fontsize=10)
            if iz == nz - 1:
                ax.set_xlabel("bearing stiffness k [N/m]")
            if ic == 0:
                ax.set_ylabel("pinion speed [rad/s]")
    axes[0, 0].legend(loc="lower right", fontsize=7, framealpha=0.7)
    if mesh is not None:
        cb = fig.colorbar(mesh, ax=axes, shrink=0.85)
        cb.set_label("RMS(II - I-static) / STD(II) [-]")
        cb.ax.axhline(thr, color="red", lw=2)
    fig.suptitle(f"Model II vs model I-static ({variable}); red contour: {100 * thr:g} %; "
                 "grey: not run (contact ratio < 1 at the static centre distance)", fontsize=10)
    return fig


def figure_resonance_curves(ds):
    """``ratio_max`` against mesh frequency / centre-distance mode frequency, one line per
    bearing stiffness, one panel per damping ratio (the healthy pair, or the first crack
    level)."""
    import matplotlib.pyplot as plt

    thr = float(ds.attrs.get("threshold", 0.1))
    nz = ds.sizes["damping_ratio"]
    fig, axes = plt.subplots(1, nz, figsize=(4.6 * nz, 3.8), squeeze=False, sharey=True,
                             layout="constrained")
    ok = _ok(ds)
    cmap = plt.get_cmap("plasma")
    k = ds.bearing_stiffness.values
    for iz in range(nz):
        ax = axes[0, iz]
        for ik, kv in enumerate(k):
            m = ok[0, iz, ik] & np.isfinite(ds["ratio_max"].values[0, iz, ik])
            if not m.any():
                continue
            x = ds.mesh_frequency.values / _mode(ds)[ik, iz]
            ax.plot(x[m], ds["ratio_max"].values[0, iz, ik][m], "o-", ms=3,
                    color=cmap(ik / max(len(k) - 1, 1)), label=f"k = {kv:.3g} N/m")
        for n in (1, 2, 3):
            ax.axvline(1.0 / n, color="grey", lw=0.8, ls="--")
        ax.axhline(thr, color="red", lw=1.2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("mesh frequency / centre-distance mode frequency [-]")
        ax.set_title(f"zeta = {100 * ds.damping_ratio.values[iz]:g} %, "
                     f"{_crack_label(float(ds.crack_depth.values[0]))}", fontsize=10)
    axes[0, 0].set_ylabel("RMS(II - I-static) / STD(II) [-]")
    axes[0, -1].legend(fontsize=7)
    return fig


def figure_iterations(ds):
    """Model II iterations: the fraction of recorded steps that re-solve, with the predictor
    and with the paper's start-of-step evaluation, and RMS(II predictor - II start)/STD(II)
    (largest over the main signals), for the deepest crack, one row per damping ratio."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, Normalize

    from .model_regimes import MAIN_SIGNALS

    ic = ds.sizes["crack_depth"] - 1
    nz = ds.sizes["damping_ratio"]
    k, w = ds.bearing_stiffness.values, ds.pinion_speed.values
    ke, we = _edges(k), _edges(w)
    d = ds["rms_ii_minus_ii_start"].sel(signal=list(MAIN_SIGNALS)).values
    with np.errstate(all="ignore"):
        dmax = np.nanmax(np.where(np.isnan(d), -np.inf, d), axis=0)
    dmax = np.where(np.isfinite(dmax), dmax, np.nan)
    panels = (("iterating_fraction", "predictor: steps iterating [-]", Normalize(0, 1)),
              ("start_iterating_fraction", "start-of-step: steps iterating [-]",
               Normalize(0, 1)),
              (None, "RMS(II pred. - II start)/STD(II) [-]", None))
    fig, axes = plt.subplots(nz, 3, figsize=(14, 3.3 * nz + 0.5), squeeze=False, sharex=True,
                             sharey=True, layout="constrained")
    for iz in range(nz):
        for j, (var, label, norm) in enumerate(panels):
            ax = axes[iz, j]
            z = (ds[var].values[ic, iz] if var else dmax[ic, iz]).T
            if norm is None:
                fin = dmax[np.isfinite(dmax) & (dmax > 0)]
                norm = LogNorm(vmin=max(float(fin.min()), 1e-4) if fin.size else 1e-3,
                               vmax=float(fin.max()) if fin.size else 1.0)
            ax.set_facecolor("#c8c8c8")
            mesh = ax.pcolormesh(ke, we, np.ma.masked_invalid(z), norm=norm, cmap="magma",
                                 shading="flat")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"zeta = {100 * ds.damping_ratio.values[iz]:g} %, "
                         f"{_crack_label(float(ds.crack_depth.values[ic]))}", fontsize=9)
            if iz == nz - 1:
                ax.set_xlabel("bearing stiffness k [N/m]")
            if j == 0:
                ax.set_ylabel("pinion speed [rad/s]")
            if iz == nz - 1:
                cb = fig.colorbar(mesh, ax=axes[:, j], location="bottom", shrink=0.8, aspect=30)
                cb.set_label(label)
                if isinstance(norm, LogNorm):  # decades only: minor labels ran into each other
                    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

                    cb.ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0), numticks=8))
                    cb.ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
                    cb.ax.xaxis.set_minor_formatter(NullFormatter())
    return fig


def figure_convergence(ds):
    """Time-step refinement at the point of the largest ratio: error of the predictor and of
    the start-of-step evaluation against the finest predictor run, and the model II / I-static
    ratio at each step (log-log)."""
    import matplotlib.pyplot as plt

    dt = ds["convergence_dt"].values
    sigs = [str(s) for s in ds["convergence_signal"].values]
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.9), layout="constrained")
    for j, s in enumerate(sigs):
        col = f"C{j}"
        # markers shrink from signal to signal: two signals with the same values stay visible
        ms = 7.5 - 1.5 * j
        ep = ds["convergence_error_predictor"].values[:-1, j]
        es = ds["convergence_error_start"].values[:, j]
        axes[0].loglog(dt[:-1], ep, "o-", color=col, ms=ms,
                       label=f"{_SIGNAL_LABELS.get(s, s)}, predictor")
        axes[0].loglog(dt, es, "s--", color=col, ms=ms,
                       label=f"{_SIGNAL_LABELS.get(s, s)}, start")
        axes[1].loglog(dt, ds["convergence_rms_ii_minus_i_static"].values[:, j], "o-",
                       color=col, ms=ms, label=_SIGNAL_LABELS.get(s, s))
    axes[0].set_xlabel("time step dt [s]")
    axes[0].set_ylabel("RMS(II ref - II) / STD(II ref) [-]")
    axes[0].set_title("model II against the finest predictor run", fontsize=10)
    thr = float(ds.attrs.get("threshold", 0.1))
    axes[1].axhline(thr, color="red", lw=1.2)
    axes[1].set_xlabel("time step dt [s]")
    axes[1].set_ylabel("RMS(II - I-static) / STD(II) [-]")
    axes[1].set_title("model II vs I-static at each step", fontsize=10)
    # one legend below both panels: inside, it covered the curves
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=4, fontsize=7)
    return fig


# ----------------------------------------------------------------------------- the page
def runup_summary(ds) -> dict:
    """The run-up's figures for the page and the CLI (``runup_*`` variables of the study)."""
    r = ds["runup_ratio_max"].values
    fr = ds["runup_frequency_ratio"].values
    k = int(np.nanargmax(r))
    sig = [str(x) for x in ds["runup_signal"].values]
    j = int(np.nanargmax(ds["runup_ratio"].values[:, k]))
    thr = float(ds.attrs.get("threshold", 0.1))
    above = np.nonzero(r > thr)[0]
    if above.size:
        spans, start = [], above[0]
        for a, b in zip(above[:-1], above[1:], strict=True):
            if b != a + 1:
                spans.append((start, a))
                start = b
        spans.append((start, above[-1]))
        text = "mesh frequency " + ", ".join(f"{fr[a]:.2f}-{fr[b]:.2f}" for a, b in spans) \
            + " times the mode's"
    else:
        text = "nowhere"
    ramp = float(ds.attrs.get("runup_ramp_time", math.nan))
    return {"max": float(r[k]), "max_ratio": float(fr[k]), "max_signal": sig[j],
            "above": int(above.size), "windows": int(r.size), "above_text": text,
            "mode": float(ds.attrs.get("runup_mode_frequency", math.nan)),
            "start_speed": float(ds.attrs.get("runup_start_speed", math.nan)),
            "end_speed": float(ds.attrs.get("runup_end_speed", math.nan)),
            "ramp_time": ramp, "window_time": ramp / max(r.size, 1),
            "ratio_lo": float(np.nanmin(fr)), "ratio_hi": float(np.nanmax(fr)),
            "iterating": float(np.nanmax(ds["runup_iterating_steps"].values)),
            "max_iterations": float(np.nanmax(ds["runup_max_iterations"].values))}


def figure_runup(ds):
    """RMS(II - I-static)/STD(II) per run-up window against the frequency ratio."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 3.6))
    fr = ds["runup_frequency_ratio"].values
    for i, sg in enumerate(ds["runup_signal"].values):
        ax.plot(fr, ds["runup_ratio"].values[i], marker=".", label=str(sg))
    ax.axhline(float(ds.attrs.get("threshold", 0.1)), color="red", lw=1)
    for x in (0.5, 1.0):
        if fr.min() <= x <= fr.max():
            ax.axvline(x, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("mesh frequency / centre-distance mode frequency [-]")
    ax.set_ylabel("RMS(II - I-static) / STD(II) [-]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def write_report(ds, out, *, command: str = "") -> Path:
    """Write ``model_regimes.html`` and ``figures/*.png`` into ``out``.

    Parameters
    ----------
    ds : xarray.Dataset
        :func:`geardyn.studies.model_regimes.model_regimes`'s result (or the NetCDF of it).
    out : path-like
        Folder.
    command : str
        The command that produced the results (shown for reproduction).

    Returns
    -------
    Path
        The HTML page.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from .model_regimes import MAIN_SIGNALS
    from .report import Report

    out = Path(out)
    s = regime_summary(ds)
    rep = Report(title="Where the centre-distance dynamics matter: model II vs model I-static",
                 out=out, subtitle="geardyn study (issue 18, item 4): RMS(II - I-static) / "
                                   "STD(II) over bearing stiffness, bearing damping, speed and "
                                   "crack depth")
    rep.heading("Finding")
    rep.paragraph(s["sentence"])
    if s["above"]:
        d, ns = s["above_detuning"]
        lo, hi = s["above_stiffness"]
        rep.paragraph(
            f"All {s['above']} points above {100 * s['threshold']:g} % have bearing stiffness "
            f"{_span((lo, hi), '.3g')} N/m and a mesh frequency whose harmonic n = "
            f"{', '.join(str(n) for n in ns)} lies within {100 * d:.3g} % of the linear "
            "centre-distance mode (the bearing mode in which the gear centres move against "
            "each other). Elsewhere in the range, model I-static (the static operating centre "
            f"distance) stays within {100 * s['threshold']:g} % of model II.")
    rep.paragraph("Largest ratio per bearing damping ratio: " + ", ".join(
        f"{100 * z:g} %: {v:.3g}" for z, v in s["by_damping"]) + ".")
    if s["compared"]:
        rep.paragraph(
            f"{s['compared']} of {s['points']} grid points ran both models; {s['not_run']} "
            f"were not run because the static operating centre distance (eq. 4) lies beyond "
            f"the map, where the contact ratio falls below 1 (no running gear pair at this "
            f"torque); {s['failed']} failed numerically (below). The crack changes the ratio "
            f"by at most {100 * s['crack_effect']:.3g} percentage points over the grid "
            "(RMS over whole revolutions: a single cracked tooth is a small part of the "
            "record).")
    rep.table(["bearing stiffness [N/m]", "centre-distance mode [Hz]",
               "static centre distance change [mm]", "points compared",
               f"points > {100 * s['threshold']:g} %", "largest ratio [-]",
               f"speeds > {100 * s['threshold']:g} % [rad/s]"],
              [(r[0], r[1], r[2] * 1e3, r[3], r[4], r[5], r[6]) for r in s["by_stiffness"]],
              caption="Per bearing stiffness (all damping ratios and crack depths)",
              left=(6,))
    fig = figure_ratio_maps(ds)
    rep.figure(fig, "ratio_maps",
               "RMS(II - I-static)/STD(II), largest over " + ", ".join(MAIN_SIGNALS)
               + ", over bearing stiffness and pinion speed. Red contour: the "
               f"{100 * s['threshold']:g} % threshold. White lines: speeds at which the mesh "
               "frequency (solid), its 2nd (dashed) or 3rd (dotted) harmonic equals the linear "
               "centre-distance mode. Grey: not run; red x: a run failed.")
    plt.close(fig)
    fig = figure_resonance_curves(ds)
    rep.figure(fig, "resonance_curves",
               "The same ratio against the mesh frequency divided by the centre-distance mode "
               "frequency (dashed lines at 1, 1/2, 1/3), one line per bearing stiffness.")
    plt.close(fig)
    rep.heading("What was explored")
    w = ds.pinion_speed.values
    step = float(np.exp(np.mean(np.diff(np.log(w))))) if w.size > 1 else math.nan
    rep.bullets([
        s["ranges"],
        "Signals: " + ", ".join(MAIN_SIGNALS) + " (the headline is the largest of their "
        "ratios); also stored per signal: y_g, centre_distance_change, mesh_stiffness.",
        "Metric: RMS(II - I-static) / STD(II) over the recorded time, the mean of the "
        "difference included; model I-static holds the mesh stiffness at the static operating "
        "centre distance of eq. 4, so the two differ only through the centre-distance "
        "dynamics.",
        f"Per point: {ds.attrs.get('rules', '')}.",
        f"Time step {ds.attrs.get('dt', math.nan):g} s, model II tolerance "
        f"{ds.attrs.get('tolerance', math.nan):g} m, stiffness map over "
        f"{ds.attrs.get('map_centre_distance_range', '')} of centre distance change.",
        f"Stiffness: the {ds.attrs.get('stiffness_method', '')} map; the difference scales "
        "with how strongly the map's K depends on the centre distance, which the FE map "
        "(--method fe) may give otherwise.",
        f"Speed grid spacing: a factor {step:.3g} between speeds. A resonance narrower than "
        "that (light bearing damping) can fall between grid points, so the largest ratio found "
        "near it is a lower bound of the peak.",
    ])
    if s["failures"]:
        rep.table(["run: failure", "points", "first point"],
                  [(k, v[1], v[2]) for k, v in s["failures"].items()],
                  caption="Failed runs (NaN in the maps)", left=(2,))
    rep.heading("Model II iterations: predictor vs the paper's start-of-step evaluation")
    it = s["iterations"]
    p, st = it["predictor"], it["start-of-step"]
    rep.paragraph(
        f"With geardyn's predictor evaluation, model II re-solved in at least one recorded step "
        f"at {p['points_iterating']} of {p['points']} points (largest fraction of steps "
        f"{p['max_fraction']:.3g}, at most {p['max_iterations']:.0f} re-solves in a step). With "
        f"the paper's start-of-step evaluation (Fig. 7) it did at {st['points_iterating']} of "
        f"{st['points']} points (mean fraction of steps {st['mean_fraction']:.3g}, largest "
        f"{st['max_fraction']:.3g}, at most {st['max_iterations']:.0f} re-solves in a step). "
        f"Steps accepted without a fixed point: {p['steps_without_fixed_point']:.0f} "
        f"(predictor), {st['steps_without_fixed_point']:.0f} (start-of-step).")
    sv = it.get("start_vs_predictor")
    if sv:
        rep.paragraph(
            f"RMS(II predictor - II start-of-step)/STD(II), largest over the main signals: "
            f"median {sv['median']:.3g}, range {_span((sv['min'], sv['max']), '.3g')}; it exceeds "
            f"the model II - I-static ratio at {sv['exceeds_model_difference']} of "
            f"{sv['points']} points. The time-step check below says which of the two "
            "evaluations is nearer the converged model II.")
    fig = figure_iterations(ds)
    rep.figure(fig, "iterations", "Fraction of recorded steps in which model II re-solved "
                                  "(predictor and start-of-step evaluation) and the difference "
                                  "between the two evaluations.")
    plt.close(fig)
    if ds.attrs.get("convergence_status") == "ok":
        rep.heading("Time-step check")
        rep.paragraph(
            f"At {ds.attrs.get('convergence_point', '')}, the point was run again with dt/2, "
            f"dt/4 and dt/8; reference: {ds.attrs.get('convergence_reference', '')}.")
        sigs = [str(x) for x in ds["convergence_signal"].values]
        rows = []
        for i, dtv in enumerate(ds["convergence_dt"].values):
            for j, sg in enumerate(sigs):
                rows.append((float(dtv), sg,
                             float(ds["convergence_error_predictor"].values[i, j]),
                             float(ds["convergence_error_start"].values[i, j]),
                             float(ds["convergence_rms_ii_minus_i_static"].values[i, j])))
        rep.table(["dt [s]", "signal", "predictor error [-]", "start-of-step error [-]",
                   "RMS(II - I-static)/STD(II) [-]"], rows, left_columns=2,
                  caption="Errors against the finest predictor run (0 at the reference itself)")
        dts = ds["convergence_dt"].values
        err_p = ds["convergence_error_predictor"].values
        err_s = ds["convergence_error_start"].values
        rat = ds["convergence_rms_ii_minus_i_static"].values
        j = int(np.argmax(rat[-1]))
        further = "further from" if np.all(err_s[0] >= err_p[0]) else \
            "not everywhere further from"
        rep.paragraph(
            f"At dt = {dts[0]:.3g} s the start-of-step evaluation is {further} the converged "
            f"model II than the predictor (largest errors {err_s[0].max():.3g} and "
            f"{err_p[0].max():.3g}); the start-of-step error falls by a factor "
            f"{err_s[0].max() / err_s[-1].max():.3g} over the {dts[0] / dts[-1]:.3g}-fold "
            f"refinement. The model II - I-static ratio of {sigs[j]} is {rat[0, j]:.3g} at "
            f"dt = {dts[0]:.3g} s and {rat[-1, j]:.3g} at {dts[-1]:.3g} s.")
        fig = figure_convergence(ds)
        rep.figure(fig, "convergence", "Time-step refinement at the point of the largest "
                                       "ratio.")
        plt.close(fig)
    elif "convergence_status" in ds.attrs:
        rep.note(f"Time-step check: {ds.attrs['convergence_status']}")
    if ds.attrs.get("runup_status") == "ok":
        ru = runup_summary(ds)
        rep.heading("A run-up through the centre-distance mode")
        rep.paragraph(
            f"The base case run up from {ru['start_speed']:.3g} to {ru['end_speed']:.3g} rad/s "
            f"in {ru['ramp_time']:g} s (mesh frequency {ru['ratio_lo']:.2g} to "
            f"{ru['ratio_hi']:.2g} times the centre-distance mode's {ru['mode']:.4g} Hz), "
            "with a constant load torque so that the mean mesh load and model I-static's "
            "static centre distance stay those of the case, and a light speed-controlled "
            f"drive. Largest RMS(II - I-static)/STD(II) in a {ru['window_time']:.3g} s window: "
            f"{ru['max']:.3g} ({ru['max_signal']}) at {ru['max_ratio']:.3g} times the mode's "
            f"frequency; above {100 * s['threshold']:g} % in {ru['above']} of {ru['windows']} "
            f"windows ({ru['above_text']}). Model II re-solved in {ru['iterating']:.3g} of its "
            f"steps at most (a window's share), at most {ru['max_iterations']:.0f} re-solves in "
            "a step.")
        fig = figure_runup(ds)
        rep.figure(fig, "runup", "Run-up: RMS(II - I-static)/STD(II) per window against the "
                                 "mesh frequency over the centre-distance mode's frequency "
                                 "(dashed: 1 and 1/2), one line per signal; the threshold in "
                                 "red.")
        plt.close(fig)
    elif "runup_status" in ds.attrs:
        rep.note(f"Run-up: {ds.attrs['runup_status']}")
    rep.heading("Reproduce")
    rep.paragraph(
        f"{'Command: ' + command + '. ' if command else ''}Sweep file: "
        f"{ds.attrs.get('sweep_origin', '')}; store {ds.attrs.get('sweep_store', '')} "
        f"({ds.attrs.get('sweep_runs', '?')} runs, {ds.attrs.get('sweep_computed_now', '?')} "
        f"computed in this call on {ds.attrs.get('workers', '?')} worker(s); "
        f"{ds.attrs.get('run_seconds', math.nan):.0f} s with the time-step check); geardyn "
        f"{ds.attrs.get('geardyn_version', '')}. Re-running the same command computes only "
        "missing runs. The results are in model_regimes.nc beside this page (xarray / NetCDF, "
        "units on every variable).")
    return rep.write("model_regimes.html",
                     footer="geardyn model II study; Xue & Howard 2018, Mech. Syst. Signal "
                            "Process.")
