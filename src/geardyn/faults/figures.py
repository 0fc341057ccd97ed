"""The figure of a faulty mesh stiffness map against the healthy one (``geardyn stiffness``)."""

from __future__ import annotations

import json

import numpy as np


def fault_labels(faulty) -> list[str]:
    """One line per fault recorded in a map's parameters (``attrs["parameters"]["faults"]``)."""
    params = faulty.attrs.get("parameters", {})
    if isinstance(params, str):
        try:
            params = json.loads(params)
        except ValueError:
            params = {}
    out = []
    for f in params.get("faults", []):
        size = {"root_crack": ("depth_m", "crack"), "spall": ("width_m", "spall width"),
                "breakage": ("height_m", "height lost"), "wear": ("depth_m", "worn")}
        key, word = size.get(f.get("type"), ("", ""))
        v = f.get(key)
        text = f"{f.get('label')}: {f.get('type')} on {f.get('gear')} tooth {f.get('tooth')}"
        if isinstance(v, int | float):
            text += f", {word} {v * 1e3:g} mm"
            if f.get("type") == "wear" and f.get("law") == "archard":
                text += " at the deepest point (Archard profile)"
        out.append(text)
    return out


def fig_faults(healthy, faulty, centre_distance_change: float = 0.0, n: int = 4000):
    """Faulty against healthy torsional mesh stiffness over the faulty map's period.

    Parameters
    ----------
    healthy, faulty : geardyn.stiffness.StiffnessMap
    centre_distance_change : float
        ``d' - d`` of the curves [m] (must lie in both maps).
    n : int
        Points per curve.

    Returns
    -------
    matplotlib.figure.Figure
        Top: ``K_t`` [N m/rad] of both maps; bottom: relative change ``K_faulty / K_healthy - 1``
        [%].
    """
    from matplotlib.figure import Figure

    th = np.linspace(0.0, faulty.period, n, endpoint=False)
    kh = healthy.torsional(th, centre_distance_change)
    kf = faulty.torsional(th, centre_distance_change)
    fig = Figure(figsize=(8.0, 5.6), layout="constrained")
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    ax.plot(np.degrees(th), kh, color="0.3", lw=1.0, label="healthy")
    ax.plot(np.degrees(th), kf, color="C3", lw=1.0, label="with the faults")
    ax.set_ylabel(r"$K_t$ [N m/rad]")
    ax.set_title(f"Mesh stiffness with the faults ({faulty.attrs.get('method', '?')}, "
                 f"$\\Delta d$ = {centre_distance_change * 1e3:g} mm)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    labels = fault_labels(faulty)
    if labels:
        ax.text(0.01, 0.02, "\n".join(labels[:6]), transform=ax.transAxes, fontsize="x-small",
                va="bottom")
    rel = np.divide(kf - kh, kh, out=np.zeros_like(kh), where=kh > 0) * 100
    ax2.plot(np.degrees(th), rel, color="C3", lw=1.0)
    ax2.set_xlabel(r"pinion rolling angle $\theta$ [deg]")
    ax2.set_ylabel("change [%]")
    ax2.grid(True, alpha=0.3)
    if "fault_gap" in getattr(faulty, "extra", {}):
        # wear: the gap the worn pair closes before it carries load, largest over the slots
        gap = np.max([np.asarray(faulty(th, centre_distance_change, "fault_gap", slot=k))
                      for k in range(3)], axis=0)
        ax3 = ax2.twinx()
        ax3.plot(np.degrees(th), gap * 1e6, color="C0", lw=1.0)
        ax3.set_ylabel("wear gap [um]", color="C0")
    return fig
