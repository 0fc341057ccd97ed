"""Figures of a crack growth result (:func:`geardyn.studies.crack_growth.crack_growth_study`).

Each function reads the result Dataset only (it never recomputes) and returns a
:class:`matplotlib.figure.Figure`; lengths are drawn in mm, stress intensity factors in
MPa m^0.5.
"""

from __future__ import annotations

import numpy as np

__all__ = ["fig_crack_path", "fig_sif", "fig_cycles", "fig_indicators", "fig_mesh_stiffness",
           "FIGURES"]


def _figure(size=(7.0, 4.6)):
    from matplotlib.figure import Figure

    return Figure(figsize=size, layout="constrained")


def fig_crack_path(ds):
    """The crack path drawn on the cracked tooth's outline (body frame, mm), with the equivalent
    straight cracks (chords) of the sampled lengths dashed."""
    fig = _figure((6.4, 6.0))
    ax = fig.subplots()
    ox, oy = ds["outline_x"].values * 1e3, ds["outline_y"].values * 1e3
    ax.fill(ox, oy, color="0.92", zorder=0)
    ax.plot(np.append(ox, ox[0]), np.append(oy, oy[0]), color="0.35", lw=0.9)
    px, py = ds["path_x"].values * 1e3, ds["path_y"].values * 1e3
    ax.plot(px, py, "-o", color="C3", ms=3, lw=1.4, label="grown crack path")
    ax.plot(px[:2], py[:2], "-", color="k", lw=2.0, label="initial crack")
    if "equivalent_depth" in ds and ds.attrs.get("indicator_stiffness", "pem") == "pem":
        for q, v in zip(ds["equivalent_depth"].values, ds["equivalent_angle"].values,
                        strict=True):
            if np.isfinite(q) and np.isfinite(v):
                ax.plot([px[0], px[0] + q * 1e3 * np.sin(v)],
                        [py[0], py[0] - q * 1e3 * np.cos(v)], "--", color="C0", lw=0.8)
        ax.plot([], [], "--", color="C0", lw=0.8, label="equivalent straight cracks (PEM)")
    half = 2.2 * abs(px[0])
    top = float(np.max(oy))
    ax.set_xlim(-half, half)
    ax.set_ylim(py.min() - 0.6 * half, top + 0.1 * half)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(f"Crack path ({ds.attrs.get('cracked_gear', '?')} tooth, "
                 f"{ds.sizes['crack_length']} tips)")
    ax.legend(loc="lower left", fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


def fig_sif(ds):
    """``K_I``, ``K_II`` and ``K_eq`` [MPa m^0.5] and the kink angle [deg] against crack
    length [mm]."""
    fig = _figure((7.0, 5.4))
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    a = ds["crack_length"].values * 1e3
    ax.plot(a, ds["K_I"].values / 1e6, "-o", ms=3, label="$K_I$")
    ax.plot(a, ds["K_II"].values / 1e6, "-s", ms=3, label="$K_{II}$")
    ax.plot(a, ds["K_eq"].values / 1e6, "--", color="0.4", label=r"$K_{eq}$ ($\Delta K$)")
    ax.axhline(0.0, color="0.6", lw=0.7)
    ax.set_ylabel(r"K [MPa m$^{0.5}$]")
    ax.set_title(f"Stress intensity factors, tooth load "
                 f"{ds.attrs.get('tooth_load_N_per_m', float('nan')) / 1e3:.4g} kN/m")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    ax2.plot(a, np.degrees(ds["kink_angle"].values), "-o", ms=3, color="C2")
    ax2.set_ylabel("kink angle [deg]")
    ax2.set_xlabel("crack length along the path [mm]")
    ax2.grid(True, alpha=0.3)
    return fig


def fig_cycles(ds):
    """Crack length [mm] and FE load-point compliance against load cycles."""
    fig = _figure((7.0, 5.4))
    ax, ax2 = fig.subplots(2, 1, sharex=True)
    n = ds["cycles"].values
    ax.plot(n, ds["crack_length"].values * 1e3, "-o", ms=3, color="C3")
    ax.set_ylabel("crack length [mm]")
    ax.set_title(f"Crack growth (Paris C = {ds.attrs.get('paris_C', float('nan')):.4g} "
                 f"m/cycle/(Pa m^0.5)^m, m = {ds.attrs.get('paris_m', float('nan')):g})")
    ax.grid(True, alpha=0.3)
    c = ds["compliance"].values
    ax2.plot(n, c / c[0], "-o", ms=3, color="C0")
    ax2.set_ylabel("compliance / initial [-]")
    ax2.set_xlabel("load cycles (one per revolution of the cracked gear)")
    ax2.grid(True, alpha=0.3)
    return fig


#: Axis labels of the metrics over the run (:data:`geardyn.studies.crack_growth.RUN_METRICS`).
_LABELS = {"NA4_run": "NA4 over the run", "NB4_run": "NB4 over the run"}


def fig_indicators(ds, metrics=("FM4", "NA4_run", "EnergyRatio"), signals=None):
    """Condition metrics against load cycles at the sampled crack lengths, each signal a line,
    its healthy baseline dashed. NA4 is the one over the run (the healthy record, then the
    samples: :mod:`geardyn.studies.crack_growth`, item 3), not the single record's (which is
    the residual's kurtosis). A panel whose values span more than a factor 30, all positive,
    has a logarithmic axis."""
    if signals is None:
        signals = [s.strip() for s in str(ds.attrs.get("indicator_signals", "")).split(",")
                   if s.strip()]
    fig = _figure((7.0, 2.3 * len(metrics) + 0.6))
    axes = np.atleast_1d(fig.subplots(len(metrics), 1, sharex=True))
    n = ds["sample_cycles"].values
    for ax, m in zip(axes, metrics, strict=True):
        seen: list[float] = []
        for i, s in enumerate(signals):
            key = f"{s}__{m}"
            if key not in ds:
                continue
            ax.plot(n, ds[key].values, "-o", ms=4, color=f"C{i}", label=s)
            base = float(ds[f"{key}_healthy"].values)
            ax.axhline(base, color=f"C{i}", ls="--", lw=0.8)
            seen += [base, *np.asarray(ds[key].values, float)]
        v = np.asarray(seen, float)
        v = v[np.isfinite(v)]
        if v.size and v.min() > 0 and v.max() > 30 * v.min():
            ax.set_yscale("log")
        ax.set_ylabel(_LABELS.get(m, m))
        ax.grid(True, alpha=0.3)
    axes[0].set_title("Indicators against load cycles (dashed: healthy pair; "
                      f"{_stiffness_label(ds)})", fontsize="medium")
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel("load cycles from the initial crack")
    return fig


def _stiffness_label(ds) -> str:
    """Which mesh stiffness the indicators used (``attrs["indicator_stiffness"]``)."""
    if ds.attrs.get("indicator_stiffness", "pem") == "fe":
        return "FE map of the grown path"
    return "PEM of the equivalent straight crack"


def fig_mesh_stiffness(ds):
    """The mesh stiffness of each sampled crack (PEM of the equivalent straight crack, or FE
    of the grown path) and of the healthy pair [N/um] against pinion angle [deg], at the design
    centre distance."""
    fig = _figure()
    ax = fig.subplots()
    th = np.degrees(ds["angle"].values)
    # in N/um (1e6 N/m): the axis's own "1e8" offset ran into the title
    ax.plot(th, ds["healthy_mesh_stiffness"].values * 1e-6, color="0.3", lw=0.9,
            label="healthy")
    for j, a in enumerate(ds["sample_length"].values):
        ax.plot(th, ds["mesh_stiffness"].values[j] * 1e-6, lw=0.9,
                label=f"{a * 1e3:.3g} mm, N = {ds['sample_cycles'].values[j]:.3g}")
    ax.set_xlabel(r"pinion angle $\theta$ [deg]")
    ax.set_ylabel(r"$k_{mb}$ [N/$\mu$m]")
    ax.set_title(f"Mesh stiffness per crack length ({_stiffness_label(ds)})")
    ax.legend(fontsize="x-small", loc="lower right")
    ax.grid(True, alpha=0.3)
    return fig


#: File name -> figure function (what ``geardyn crack-growth`` writes).
FIGURES = {
    "fig_crack_path.png": fig_crack_path,
    "fig_sif.png": fig_sif,
    "fig_cycles.png": fig_cycles,
    "fig_indicators.png": fig_indicators,
    "fig_mesh_stiffness.png": fig_mesh_stiffness,
}
