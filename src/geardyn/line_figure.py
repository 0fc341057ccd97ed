"""A line figure drawn from plain curves (arrays and text).

The stiffness figures (:mod:`geardyn.stiffness.plots`, the analogues of Xue & Howard (2018)
Figs. 5 and 6) evaluate their maps where the maps are and hand this module the curves. Drawing
them needs matplotlib and numpy only: the process that draws a run's report figures
(:mod:`geardyn.studies.figure_process`) then neither imports the map code and numba (0.3 s,
56 MB) nor loads numba's compiled map look-up to evaluate a map (0.3 s, 50 MB; measured
2026-11-27 on the 2-core machine).

A curves specification is a plain ``dict`` (it pickles without geardyn's classes):

``x`` : ndarray
    Abscissa of every line (unit in ``xlabel``).
``lines`` : list of dict
    Each ``{"y": ndarray, "label": str}``, optionally with a matplotlib ``"color"``.
``xlabel``, ``ylabel``, ``title`` : str
``ylim`` : (float, float) or None
``legend_columns`` : int
    Columns of the legend under the axes.
``figsize`` : (float, float)
    Inches.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["draw_line_figure"]



def draw_line_figure(spec: Mapping):
    """The figure of a curves specification (module docstring): the lines on one axes, a grid,
    and the legend under the axes, outside the data.

    Parameters
    ----------
    spec : mapping
        The curves (module docstring).

    Returns
    -------
    matplotlib.figure.Figure
        Not attached to pyplot.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=tuple(spec.get("figsize", (7.5, 4.8))), layout="constrained")
    ax = fig.add_subplot()
    for line in spec["lines"]:
        style = {"color": line["color"]} if "color" in line else {}
        ax.plot(spec["x"], line["y"], label=line["label"], **style)
    ax.set_xlabel(spec["xlabel"])
    ax.set_ylabel(spec["ylabel"])
    if spec.get("ylim") is not None:
        ax.set_ylim(*spec["ylim"])
    ax.set_title(spec["title"])
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        # constrained layout makes room for a legend placed "outside"
        fig.legend(handles, labels, loc="outside lower center",
                   ncols=min(int(spec.get("legend_columns", 3)), len(handles)),
                   fontsize="small", frameon=False)
    return fig
