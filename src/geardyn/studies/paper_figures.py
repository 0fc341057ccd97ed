"""Figures of the paper's case study (analogues of Xue & Howard's Figs. 8-23).

Pure functions: simulation Datasets and diagnosis results in, :class:`matplotlib.figure.Figure`
out (no pyplot state). Model I is drawn on the left and model II on the right, as in the paper.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["SIGNALS", "fig8_design_parameters", "fig9_iteration", "fig10_stiffness",
           "fig_tsa", "fig_spectra", "fig_residuals", "fig_pwvd_pair", "fig_demodulation_pair",
           "fig_analytic_pair", "crack_times", "fig_measured_tsa", "fig_model_comparison"]

#: The paper's three signals: name -> (label, unit, symbol)
SIGNALS = {
    "v_yg": ("output gear vertical velocity", "m/s", r"$\dot y_g$"),
    "omega_p": ("input pinion angular velocity", "rad/s", r"$\dot\theta_p$"),
    "transmission_error": ("transmission error", "rad",
                           r"$\theta_p - (r_{b2}/r_{b1})\,\theta_g$"),
}
MODELS = ("I", "II")
COLORS = {"I": "#1f77b4", "II": "#d62728", "I-static": "#2ca02c"}


def _new_figure(**kwargs) -> Figure:
    """A :class:`matplotlib.figure.Figure`; matplotlib is imported here, when a figure is drawn,
    so a run that takes every figure from the cache does not import it (issue 16)."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def _v(ds, name: str) -> np.ndarray:
    """The values of variable ``name`` of a record: an :class:`xarray.Dataset`, or a mapping of
    name -> array (what the study hands to the figure process, which then needs no xarray)."""
    return np.asarray(ds[name])


def crack_times(ds, crack_angle: float, period: float = 2 * math.pi) -> np.ndarray:
    """Times [s] at which the pinion angle passes ``crack_angle`` [rad] modulo ``period``
    [rad]: the period of the faulty stiffness map (:attr:`StiffnessMap.period`), one pinion
    revolution (2 pi) for a fault on the pinion, one gear revolution (``2 pi z2 / z1`` of
    pinion angle) for a fault on the gear."""
    th = _v(ds, "theta_p")
    t = _v(ds, "time")
    k0 = math.ceil((th[0] - crack_angle) / period)
    k1 = math.floor((th[-1] - crack_angle) / period)
    targets = crack_angle + period * np.arange(k0, k1 + 1)
    return np.interp(targets, th, t)


def _window(ds, t0: float, t1: float):
    t = _v(ds, "time")
    return (t >= t0) & (t <= t1)


def _plain_axis(ax) -> None:
    """No offset or scientific notation on the y axis (values read as printed)."""
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)


def fig8_design_parameters(ds, crack_angle: float | None, window: tuple[float, float],
                           fault: str = "crack", period: float = 2 * math.pi) -> Figure:
    """Fig. 8 analogue: centre distance change, operating pressure angle and contact ratio of
    model II against time from the start of the record, with the fault's events marked
    (``fault``: the title's word for it, "crack" or "fault"; ``period``: as in
    :func:`crack_times`).

    The physical contact ratio and the paper's eq. 8 value differ by more than their
    variation, so each has its own panel (on one axis both would look flat).

    ``ds``, and the records of :func:`fig9_iteration` and :func:`fig10_stiffness`: a model
    record (:class:`xarray.Dataset`) or a mapping of its variable names (``time`` [s] among
    them) to arrays."""
    fig = _new_figure(figsize=(8.5, 8.6), layout="constrained")
    axs = fig.subplots(4, 1, sharex=True)
    sel = _window(ds, *window)
    t_all = _v(ds, "time")
    t0 = float(t_all[0])
    t = t_all[sel] - t0
    axs[0].plot(t, _v(ds, "centre_distance_change")[sel] * 1e3, lw=0.9)
    axs[0].set_ylabel("centre distance change\n$d(t) - d$ [mm]")
    axs[1].plot(t, np.degrees(_v(ds, "pressure_angle")[sel]), lw=0.9)
    axs[1].set_ylabel("operating pressure\nangle [deg]")
    axs[2].plot(t, _v(ds, "contact_ratio")[sel], lw=0.9, color="tab:green")
    axs[2].set_ylabel("contact ratio,\nphysical [-]")
    axs[3].plot(t, _v(ds, "contact_ratio_eq8")[sel], lw=0.9, color="tab:purple")
    axs[3].set_ylabel("contact ratio,\npaper eq. 8 [-]")
    axs[3].set_xlabel("time from the start of the record [s]")
    if crack_angle is not None:
        for tc in crack_times(ds, crack_angle, period):
            if window[0] <= tc <= window[1]:
                for ax in axs:
                    ax.axvline(tc - t0, color="0.4", ls="--", lw=0.8)
        axs[0].set_title(f"model II ({fault} events dashed)", fontsize=10)
    for ax in axs:
        ax.grid(alpha=0.3)
        _plain_axis(ax)
    axs[3].ticklabel_format(axis="x", style="plain", useOffset=False)
    return fig


def fig9_iteration(ds_scheme, ds_default, crack_angle: float | None,
                   window: tuple[float, float], tolerance: float,
                   period: float = 2 * math.pi) -> Figure:
    """Fig. 9 analogue: |b1 - b2| before and after the iteration, iterations per step and the
    mesh stiffness used, for the paper's start-of-step scheme; the default (predictor) run's
    first-solve |b1 - b2| is shown for comparison."""
    fig = _new_figure(figsize=(8.5, 7.5), layout="constrained")
    axs = fig.subplots(3, 1, sharex=True)
    sel = _window(ds_scheme, *window)
    t = _v(ds_scheme, "time")[sel]
    axs[0].plot(t, _v(ds_scheme, "residual_before")[sel] * 1e6, color="tab:red", lw=0.8,
                label="before iteration (paper's start-of-step scheme)")
    axs[0].plot(t, _v(ds_scheme, "residual_after")[sel] * 1e6, color="k", lw=0.8,
                label="after iteration")
    seld = _window(ds_default, *window)
    axs[0].plot(_v(ds_default, "time")[seld], _v(ds_default, "residual_before")[seld] * 1e6,
                color="tab:green", lw=0.8, label="geardyn default (predictor), first solve")
    axs[0].axhline(tolerance * 1e6, color="0.5", ls=":", lw=1, label="tolerance")
    axs[0].set_ylabel(r"$|b_1 - b_2|$ [$\mu$m]")
    axs[0].legend(fontsize=7, loc="upper right")
    axs[1].step(t, _v(ds_scheme, "iterations")[sel], where="mid", lw=0.8)
    axs[1].set_ylabel("iterations [-]")
    axs[2].plot(t, _v(ds_scheme, "mesh_stiffness")[sel], lw=0.8)
    axs[2].set_ylabel(r"$K_m(\theta, d)$ [N/m]")
    axs[2].set_xlabel("time [s]")
    if crack_angle is not None:
        for tc in crack_times(ds_scheme, crack_angle, period):
            if window[0] <= tc <= window[1]:
                for ax in axs:
                    ax.axvline(tc, color="0.4", ls="--", lw=0.8)
    for ax in axs:
        ax.grid(alpha=0.3)
    return fig


def fig10_stiffness(ds_i, ds_ii, crack_angle: float | None, window: tuple[float, float],
                    ds_i_static=None, period: float = 2 * math.pi) -> Figure:
    """Fig. 10 analogue: the mesh stiffness the models used, K_m(theta) and K_m(theta, d).

    With ``ds_i_static`` (a model I-static record) its K_m(theta, d_s) at the static operating
    centre distance is drawn dashed over model II's (the paper has no such curve)."""
    fig = _new_figure(figsize=(8.5, 3.8), layout="constrained")
    ax = fig.subplots()
    curves = [(ds_i, r"model I, $K_m(\theta)$", "I", "-", 0.9),
              (ds_ii, r"model II, $K_m(\theta, d)$", "II", "-", 0.9)]
    if ds_i_static is not None:
        curves.append((ds_i_static, r"model I-static, $K_m(\theta, d_s)$ (dashed)", "I-static",
                       "--", 1.1))
    for ds, lab, m, ls, lw in curves:
        sel = _window(ds, *window)
        ax.plot(_v(ds, "time")[sel], _v(ds, "mesh_stiffness")[sel], lw=lw, ls=ls,
                label=lab, color=COLORS[m])
    if crack_angle is not None:
        for tc in crack_times(ds_ii, crack_angle, period):
            if window[0] <= tc <= window[1]:
                ax.axvline(tc, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("mesh stiffness along the LOA [N/m]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def _grid(title_fn, plot_fn, diags: dict, signals=SIGNALS, figsize=(11.0, 8.0)) -> Figure:
    fig = _new_figure(figsize=figsize, layout="constrained")
    axs = fig.subplots(len(signals), 2, squeeze=False)
    for i, sig in enumerate(signals):
        for j, m in enumerate(MODELS):
            ax = axs[i, j]
            plot_fn(ax, diags[m].signals[sig], sig, m)
            ax.set_title(title_fn(sig, m), fontsize=9)
            ax.grid(alpha=0.3)
    return fig


def _deg_axis(ax) -> None:
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("pinion shaft angle [deg]")


def fig_tsa(diags: dict) -> Figure:
    """Fig. 11 analogue: time synchronous averages over one pinion revolution."""

    def plot(ax, sd, sig, m):
        ang = np.degrees(sd.tsa.angle - sd.tsa.angle[0])
        ax.plot(ang, sd.tsa.average, lw=0.7, color=COLORS[m])
        ax.set_ylabel(f"{SIGNALS[sig][2]} [{SIGNALS[sig][1]}]")
        _deg_axis(ax)

    return _grid(lambda s, m: f"model {m}: TSA of {SIGNALS[s][0]}", plot, diags)


def fig_spectra(diags: dict, teeth: int, max_order: int = 160, floor_db: float = 120.0) -> Figure:
    """Fig. 12 analogue: RMS order spectra (dB re 1 unit) of the TSAs as stems, mesh harmonics
    marked.

    The mean is removed and the DC bin (order 0) is not drawn: the TSA's mean (e.g. the pinion's
    114 rad/s) is no vibration, and after removing it the DC bin is round-off (about -400 dB)
    that would set the scale. The axis shows ``floor_db`` dB below the largest line, as
    ``geardyn diagnose``'s spectrum plot does.
    """
    from ..diagnostics import order_spectrum

    def plot(ax, sd, sig, m):
        sp = order_spectrum(sd.tsa.average - np.mean(sd.tsa.average), scaling="rms", db=True)
        k = (sp.orders >= 1) & (sp.orders <= max_order)
        orders, amp = sp.orders[k], np.asarray(sp.amplitude)[k]
        finite = amp[np.isfinite(amp)]
        top = float(finite.max()) if finite.size else 0.0
        floor = top - floor_db
        ax.vlines(orders, floor, np.maximum(amp, floor), lw=0.8, color=COLORS[m])
        for h in range(teeth, max_order + 1, teeth):
            ax.axvline(h, color="0.6", ls=":", lw=0.7)
        ax.set_xlim(0, max_order)
        ax.set_ylim(floor, top + 10.0)
        ax.set_xlabel("shaft order [-]")
        ax.set_ylabel(f"RMS [dB re 1 {SIGNALS[sig][1]}]")

    return _grid(lambda s, m: f"model {m}: RMS spectrum of {SIGNALS[s][0]}", plot, diags)


def fig_residuals(diags: dict) -> Figure:
    """Fig. 13 analogue: residual signals (mesh harmonics removed)."""

    def plot(ax, sd, sig, m):
        ang = np.degrees(sd.tsa.angle - sd.tsa.angle[0])
        ax.plot(ang, sd.residual, lw=0.7, color=COLORS[m])
        ax.set_ylabel(f"residual [{SIGNALS[sig][1]}]")
        _deg_axis(ax)
        ax.text(0.02, 0.92, f"kurtosis {sd.residual_kurtosis:.2f}", transform=ax.transAxes,
                fontsize=8, va="top")

    return _grid(lambda s, m: f"model {m}: residual of {SIGNALS[s][0]}", plot, diags)


def _pwvd_again(diag, sd, which: str):
    """The PWVD :func:`geardyn.diagnostics.diagnose` computed for ``sd`` (same input and
    settings, so the same numbers), for a diagnosis stored without its distributions."""
    from ..diagnostics.tfd import pwvd

    x = sd.tsa.average if which == "tsa" else sd.residual
    return pwvd(x, window_length=diag.settings.get("pwvd_window_length"),
                max_order=diag.settings["pwvd_max_order"])


def fig_pwvd_pair(diags: dict, sig: str, which: str, teeth: int, max_order: float) -> Figure:
    """Figs. 14/15/18/21 analogues: PWVD of the TSA (``which="tsa"``) or of the residual."""
    fig = _new_figure(figsize=(11.0, 4.3), layout="constrained")
    axs = fig.subplots(1, 2, sharey=True)
    for ax, m in zip(axs, MODELS, strict=True):
        sd = diags[m].signals[sig]
        pw = sd.pwvd_tsa if which == "tsa" else sd.pwvd_residual
        if pw.distribution.size == 0:  # a diagnosis kept without its distributions (memory):
            pw = _pwvd_again(diags[m], sd, which)  # the same PWVD, computed for this figure
        k = pw.orders <= max_order
        n_k = int(np.count_nonzero(k))
        if k[:n_k].all():  # ascending orders: the kept ones are a slice (a view, no copy)
            k = slice(0, n_k)
        n_ang = pw.angle.size
        d = pw.distribution[:, k] if pw.distribution.shape[0] == n_ang else \
            pw.distribution[k, :].T
        # cells on a uniform grid: angle bins tile 0..360 deg exactly (no blank strip at
        # 360 deg), order bins centred on their orders; drawn as an image (a quad mesh of
        # millions of cells took 0.9 s per figure, most of the run's figure time)
        o = pw.orders[k]
        step = o[1] - o[0] if o.size > 1 else 1.0
        vmax = float(max(d.max(), -d.min())) or 1.0  # max |d| without an |d| array
        # the image holds a float32 copy (display only: 8-bit colours), not a view of the
        # float64 distribution, which is freed before the next model's is computed; matplotlib
        # then scales in float32 too (a cold run's memory peak was drawing these figures)
        img = np.ascontiguousarray(d.T, dtype=np.float32)
        del pw, d
        # interpolation_stage="data": the nearest cell picked first, then coloured, instead of
        # colouring every cell first (matplotlib's choice when it shrinks an image): the same
        # pixels on matplotlib 3.11, one colour step apart at a few colour edges on 3.8
        im = ax.imshow(img, origin="lower", aspect="auto", interpolation="nearest",
                       interpolation_stage="data",
                       extent=(0.0, 360.0, o[0] - step / 2, o[-1] + step / 2),
                       cmap="viridis", vmin=0, vmax=vmax)
        ax.set_ylim(max(o[0] - step / 2, 0.0), o[-1] + step / 2)
        for h in range(teeth, int(max_order) + 1, teeth):
            ax.axhline(h, color="w", ls=":", lw=0.5, alpha=0.6)
        ax.set_title(f"model {m}: PWVD of the {'TSA' if which == 'tsa' else 'residual'} of "
                     f"{SIGNALS[sig][0]}", fontsize=9)
        _deg_axis(ax)
        ax.set_ylabel("shaft order [-]")
        fig.colorbar(im, ax=ax, label=f"PWVD [({SIGNALS[sig][1]})$^2$]", shrink=0.85)
    return fig


def fig_demodulation_pair(diags: dict, sig: str) -> Figure:
    """Figs. 16/19/22 analogues: narrowband envelope, amplitude and phase modulation."""
    fig = _new_figure(figsize=(11.0, 7.5), layout="constrained")
    axs = fig.subplots(3, 2, sharex=True)
    unit = SIGNALS[sig][1]
    for j, m in enumerate(MODELS):
        sd = diags[m].signals[sig]
        dem = sd.demodulation
        ang = np.degrees(dem.angle - dem.angle[0])
        axs[0, j].plot(ang, dem.envelope, lw=0.8, color=COLORS[m])
        axs[0, j].set_ylabel(f"envelope [{unit}]")
        axs[0, j].set_title(f"model {m}: {SIGNALS[sig][0]}, band {dem.carrier_order} "
                            f"+/- {dem.bandwidth} orders (kurtosis {sd.envelope_kurtosis:.2f})",
                            fontsize=9)
        axs[1, j].plot(ang, dem.am, lw=0.8, color=COLORS[m])
        axs[1, j].set_ylabel(f"AM [{unit}]")
        axs[1, j].set_title(f"amplitude modulation (kurtosis {sd.am_kurtosis:.2f})", fontsize=9)
        axs[2, j].plot(ang, np.degrees(dem.pm), lw=0.8, color=COLORS[m])
        axs[2, j].set_ylabel("PM [deg]")
        axs[2, j].set_title(f"phase modulation (kurtosis {sd.pm_kurtosis:.2f})", fontsize=9)
        _deg_axis(axs[2, j])
        for i in range(3):
            axs[i, j].grid(alpha=0.3)
    return fig


def fig_analytic_pair(diags: dict, sig: str) -> Figure:
    """Figs. 17/20/23 analogues: the baseband analytic signal of the demodulated harmonic in the
    complex plane (radius = AM, angle = PM), both models."""
    fig = _new_figure(figsize=(6.0, 5.6), layout="constrained")
    ax = fig.subplots()
    for m in MODELS:
        z = diags[m].signals[sig].demodulation.baseband
        ax.plot(z.real, z.imag, lw=0.8, color=COLORS[m], label=f"model {m}")
        ax.plot(z.real[:1], z.imag[:1], "o", color=COLORS[m], ms=4)
    ax.axhline(0, color="0.6", lw=0.6)
    ax.axvline(0, color="0.6", lw=0.6)
    ax.set_aspect("equal", adjustable="datalim")
    unit = SIGNALS[sig][1]
    ax.set_xlabel(f"real part [{unit}]")
    ax.set_ylabel(f"imaginary part [{unit}]")
    ax.set_title(f"analytic signal of the demodulated harmonic: {SIGNALS[sig][0]}", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


#: Variants of the measurement section drawn by :func:`fig_measured_tsa`: name -> (colour,
#: line width, label).
MEASURED_STYLE = {"ideal": ("black", 0.8, "ideal (no errors, no noise)"),
                  "errors": ("#1f77b4", 0.8, "tooth errors only"),
                  "errors+noise": ("#d62728", 0.6, "tooth errors + noise (realistic)")}


def fig_measured_tsa(tsas: dict, model: str, faulty: str = "cracked") -> Figure:
    """TSA of the housing acceleration (tachometer TSA, in g) over one revolution of the
    tachometer's shaft, healthy (top) and cracked (bottom), for the measurement variants of
    :data:`MEASURED_STYLE` (:mod:`geardyn.studies.paper_measurement`).

    Parameters
    ----------
    tsas : dict
        ``(variant, state)`` -> TSA [m/s^2].
    model : str
        Model of the simulations (title).
    faulty : str
        The titles' word for the faulty state ("cracked", or "faulty" when the fault is not a
        crack); the data's key stays ``"cracked"``.
    """
    g = 9.80665
    fig = _new_figure(figsize=(11.0, 6.0), layout="constrained")
    axs = fig.subplots(2, 1, sharex=True)
    for ax, state in zip(axs, ("healthy", "cracked"), strict=True):
        for name, (color, lw, label) in MEASURED_STYLE.items():
            a = tsas.get((name, state))
            if a is None:
                continue
            ang = np.arange(a.size) * 360.0 / a.size
            ax.plot(ang, a / g, lw=lw, color=color, label=label)
        shown = faulty if state == "cracked" else state
        ax.set_title(f"model {model}, {shown}: TSA of the housing acceleration (tachometer)",
                     fontsize=9)
        ax.set_ylabel("acceleration [g]")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8, loc="upper right")
    _deg_axis(axs[1])
    axs[1].set_xlabel("shaft angle from the tachometer pulse [deg]")
    return fig


def fig_model_comparison(comparison: dict, faulty: str = "cracked") -> Figure:
    """RMS(II - I) / STD(II) and RMS(II - I-static) / STD(II) per signal, one panel per state.

    Parameters
    ----------
    comparison : dict
        ``state -> {"signals": {signal: {"rms_ii_minus_i", "rms_ii_minus_i_static", ...}}}``
        (``summary["model_comparison"]`` of the study).
    faulty : str
        The titles' word for the state ``"cracked"`` ("faulty" when the fault is not a crack).
    """
    states = [st for st in ("cracked", "healthy") if st in comparison]
    fig = _new_figure(figsize=(10.0, 3.4 * max(1, len(states))), layout="constrained")
    axs = np.atleast_1d(fig.subplots(max(1, len(states)), 1, squeeze=False)[:, 0])
    for ax, st in zip(axs, states, strict=False):
        sig = comparison[st]["signals"]
        names = list(sig)
        x = np.arange(len(names))
        for off, key, lab, m in ((-0.2, "rms_ii_minus_i", "RMS(II - I) / STD(II)", "I"),
                                 (0.2, "rms_ii_minus_i_static", "RMS(II - I-static) / STD(II)",
                                  "I-static")):
            v = np.array([sig[n][key] if sig[n][key] is not None else np.nan for n in names],
                         dtype=float)
            ax.bar(x + off, 100.0 * v, width=0.4, label=lab, color=COLORS[m])
        ax.set_yscale("log")
        ax.set_xticks(x)
        ax.set_xticklabels([n.replace("_", " ") for n in names], rotation=20, fontsize=8)
        ax.set_ylabel("% of STD(II)")
        shown = faulty if st == "cracked" else st
        ax.set_title(f"{shown} pair: distance of model I and model I-static from model II",
                     fontsize=9)
        ax.grid(alpha=0.3, which="both", axis="y")
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig
