"""Figures of the diagnostics chain (matplotlib, object API only: no pyplot global state).

Every function returns a new :class:`matplotlib.figure.Figure` that can be saved with
``fig.savefig(path)`` under any backend (Agg is used for PNG). matplotlib is imported lazily.
Angles are shown in degrees over one revolution (0-360 deg), orders are shaft orders.
"""

from __future__ import annotations

import numpy as np

from .demodulation import DemodulationResult
from .spectra import OrderSpectrum, order_spectrum
from .tfd import PWVDResult
from .tsa import TSAResult

__all__ = [
    "plot_tsa",
    "plot_order_spectrum",
    "plot_residual",
    "plot_pwvd",
    "plot_demodulation",
    "plot_analytic_signal",
]


def _figure(figsize):
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


#: An axis label's unit where the data gave none (a CSV without a unit row): not "[-]", which
#: would say the signal is dimensionless.
NO_UNIT = "unit not given"


def _unit(unit: str) -> str:
    return f" [{unit or NO_UNIT}]"


def _angle_axis(n: int) -> np.ndarray:
    return 360.0 * np.arange(n) / n


def plot_tsa(tsa, *, label: str = "signal", unit: str = "", title: str | None = None,
             figsize=(8.0, 3.2)):
    """Synchronous average over one revolution, against shaft angle 0-360 deg.

    Parameters
    ----------
    tsa : TSAResult or array_like, shape (N,)
        The average (unit ``unit``).
    label : str
        Name of the signal for the axis label.
    unit : str
        Unit of the signal, e.g. ``"m/s"``.
    title : str, optional
        Figure title; default mentions the number of averages.
    figsize : tuple of float
        Size [in].

    Returns
    -------
    matplotlib.figure.Figure
    """
    if isinstance(tsa, TSAResult):
        y = np.asarray(tsa.average)
        default = f"TSA of {label} ({tsa.n_averages} revolutions averaged)"
    else:
        y = np.asarray(tsa, dtype=float)
        default = f"TSA of {label}"
    fig = _figure(figsize)
    ax = fig.add_subplot()
    ax.plot(_angle_axis(y.shape[-1]), y, lw=0.8)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("shaft angle [deg]")
    # a column named with its unit ("acc [g]") keeps it once
    ax.set_ylabel(label if unit and label.rstrip().endswith(f"[{unit}]") else label + _unit(unit))
    ax.set_title(title or default)
    ax.grid(True, alpha=0.3)
    return fig


def plot_order_spectrum(spectrum, *, teeth: int | None = None, max_order: float | None = None,
                        label: str = "signal", unit: str = "", title: str | None = None,
                        figsize=(8.0, 3.2)):
    """RMS order spectrum in dB with the mesh harmonics marked.

    Parameters
    ----------
    spectrum : OrderSpectrum or array_like
        A spectrum (converted to dB re 1 if linear) or a one-revolution TSA (its RMS spectrum
        in dB re 1 is computed).
    teeth : int, optional
        Z; mesh harmonics m*Z are marked with dashed lines.
    max_order : float, optional
        Upper limit of the order axis [-]; default 7 mesh harmonics or all.
    label, unit : str
        Signal name and unit (the dB reference is 1 unit).
    title : str, optional
        Title.
    figsize : tuple of float
        Size [in].

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(spectrum, OrderSpectrum):
        spectrum = order_spectrum(np.asarray(spectrum, dtype=float), scaling="rms", db=True)
    amp = np.asarray(spectrum.amplitude)
    if not spectrum.db:
        amp = 20 * np.log10(np.maximum(amp, np.finfo(float).tiny) / spectrum.db_ref)
    orders = spectrum.orders
    if max_order is None:
        max_order = min(orders[-1], 7 * teeth) if teeth else orders[-1]
    sel = orders <= max_order
    fig = _figure(figsize)
    ax = fig.add_subplot()
    finite = amp[sel][amp[sel] > -1000]
    floor = (finite.max() - 120.0) if finite.size else -120.0
    ax.vlines(orders[sel], floor, np.maximum(amp[sel], floor), lw=0.8)
    if teeth:
        for m in range(1, int(max_order // teeth) + 1):
            ax.axvline(m * teeth, color="tab:red", ls="--", lw=0.7, alpha=0.7,
                       label="mesh harmonics" if m == 1 else None)
        ax.legend(loc="upper right", fontsize="small")
    ax.set_xlim(0, max_order)
    ax.set_ylim(bottom=floor)
    ax.set_xlabel("shaft order [-]")
    ref = f"1 {unit}" if unit else "1"
    ax.set_ylabel(f"{spectrum.scaling.upper()} amplitude [dB re {ref}]")
    ax.set_title(title or f"{spectrum.scaling.upper()} order spectrum of {label}")
    ax.grid(True, alpha=0.3)
    return fig


def plot_residual(residual, *, label: str = "signal", unit: str = "",
                  title: str | None = None, figsize=(8.0, 3.2)):
    """Residual signal over one revolution, against shaft angle 0-360 deg.

    Parameters
    ----------
    residual : array_like, shape (N,)
        Residual (unit ``unit``).
    label, unit, title, figsize
        As :func:`plot_tsa`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    return plot_tsa(np.asarray(residual, dtype=float), label=f"residual of {label}", unit=unit,
                    title=title or f"Residual signal of {label}", figsize=figsize)


def plot_pwvd(result: PWVDResult, *, max_order: float | None = None, teeth: int | None = None,
              scale: str = "linear", label: str = "signal", unit: str = "",
              title: str | None = None, figsize=(7.0, 5.0)):
    """Image of a PWVD: shaft angle [deg] horizontally, shaft order vertically.

    Parameters
    ----------
    result : PWVDResult
        The distribution (unit^2).
    max_order : float, optional
        Upper order shown [-]; default 6 mesh harmonics when ``teeth`` is given, else all.
    teeth : int, optional
        Z, to mark the mesh harmonics on the order axis.
    scale : {"linear", "db"}
        Colour scale: linear (negative interference values clipped at 0) or dB re the
        maximum (floor -60 dB).
    label, unit, title, figsize
        As :func:`plot_tsa`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    dist = np.asarray(result.distribution)
    orders = result.orders
    if max_order is None:
        max_order = min(orders[-1], 6 * teeth + 0.5 * teeth) if teeth else orders[-1]
    sel = orders <= max_order
    img = np.maximum(dist[:, sel], 0.0).T
    cbar_label = f"PWVD [({unit})^2]" if unit else f"PWVD [{NO_UNIT}]"
    if scale == "db":
        peak = img.max() if img.size and img.max() > 0 else 1.0
        img = 10 * np.log10(np.maximum(img / peak, 1e-6))
        cbar_label = "PWVD [dB re max]"
    fig = _figure(figsize)
    ax = fig.add_subplot()
    ang = result.angle_deg
    im = ax.imshow(img, origin="lower", aspect="auto", cmap="viridis",
                   extent=(ang[0], ang[-1] + (ang[1] - ang[0] if ang.size > 1 else 1),
                           orders[sel][0], orders[sel][-1]))
    if teeth:
        ax.set_yticks(np.arange(0, max_order + 1e-9, teeth))
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("shaft angle [deg]")
    ax.set_ylabel("shaft order [-]")
    ax.set_title(title or f"PWVD of {label}")
    fig.colorbar(im, ax=ax, label=cbar_label)
    return fig


def plot_demodulation(dem: DemodulationResult, *, label: str = "signal", unit: str = "",
                      title: str | None = None, figsize=(8.0, 7.0)):
    """Narrowband envelope, amplitude modulation and phase modulation against shaft angle.

    Parameters
    ----------
    dem : DemodulationResult
        Output of :func:`narrowband_demodulation`.
    label, unit, title, figsize
        As :func:`plot_tsa`.

    Returns
    -------
    matplotlib.figure.Figure
        Three stacked panels (envelope [unit], AM [unit], PM [deg]).
    """
    ang = np.degrees(dem.angle)
    fig = _figure(figsize)
    axes = fig.subplots(3, 1, sharex=True)
    env_note = "carrier removed" if dem.envelope_excludes_carrier else "carrier kept"
    axes[0].plot(ang, dem.envelope, lw=0.8)
    axes[0].set_ylabel("envelope" + _unit(unit))
    axes[0].set_title(f"narrowband envelope ({env_note})", fontsize="medium")
    axes[1].plot(ang, dem.am, lw=0.8)
    axes[1].set_ylabel("AM" + _unit(unit))
    axes[1].set_title("amplitude modulation", fontsize="medium")
    axes[2].plot(ang, dem.pm_deg, lw=0.8)
    axes[2].set_ylabel("PM [deg]")
    axes[2].set_title("phase modulation", fontsize="medium")
    axes[2].set_xlabel("shaft angle [deg]")
    axes[2].set_xlim(0, 360)
    axes[2].set_xticks(np.arange(0, 361, 45))
    for ax in axes:
        ax.grid(True, alpha=0.3)
    lo, hi = dem.band
    fig.suptitle(title or f"Demodulation of {label} about order {dem.carrier_order} "
                 f"(mesh harmonic {dem.harmonic}, orders {lo}-{hi})")
    return fig


def plot_analytic_signal(dem: DemodulationResult, *, label: str = "signal", unit: str = "",
                         title: str | None = None, figsize=(10.0, 4.5)):
    """Baseband analytic signal in the complex plane and its real/imaginary parts vs angle.

    The baseband :math:`z e^{-iK\\theta}` has radius = AM and angle = PM.

    Parameters
    ----------
    dem : DemodulationResult
        Output of :func:`narrowband_demodulation`.
    label, unit, title, figsize
        As :func:`plot_tsa`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    b = dem.baseband
    ang = np.degrees(dem.angle)
    fig = _figure(figsize)
    ax1, ax2 = fig.subplots(1, 2, width_ratios=(1, 1.6))
    ax1.plot(b.real, b.imag, lw=0.8)
    ax1.plot([0], [0], "k+")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.set_xlabel("real part" + _unit(unit))
    ax1.set_ylabel("imaginary part" + _unit(unit))
    ax1.set_title("complex plane", fontsize="medium")
    ax1.grid(True, alpha=0.3)
    ax2.plot(ang, b.real, lw=0.8, label="real")
    ax2.plot(ang, b.imag, lw=0.8, label="imaginary")
    ax2.set_xlim(0, 360)
    ax2.set_xticks(np.arange(0, 361, 45))
    ax2.set_xlabel("shaft angle [deg]")
    ax2.set_ylabel("baseband analytic signal" + _unit(unit))
    ax2.legend(fontsize="small")
    ax2.grid(True, alpha=0.3)
    fig.suptitle(title or f"Analytic signal of {label} about order {dem.carrier_order}")
    return fig
