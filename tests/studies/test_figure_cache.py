"""The report's figures through the disk cache (issue 16.6): same inputs, same PNG, not drawn
again; other inputs, other code or no cache: drawn."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from geardyn.studies.paper_result import FigureStore, RenderedFigure  # noqa: E402

CALLS: list = []


def draw(y, *, title="t", extra=None):
    CALLS.append(title)
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.plot(np.asarray(y))
    ax.set_title(title)
    return fig


def test_same_inputs_come_from_the_cache_other_inputs_are_drawn(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    CALLS.clear()
    y = np.linspace(0.0, 1.0, 50)
    a, b = FigureStore(), FigureStore()
    a.cached("f", draw, y, title="one")
    b.cached("f", draw, y.copy(), title="one")       # equal content, another array object
    assert CALLS == ["one"]
    assert isinstance(b["f"], RenderedFigure) and b["f"].png == a["f"].png
    assert b["f"].png[:8] == b"\x89PNG\r\n\x1a\n"
    y2 = y.copy()
    y2[7] += 1e-12                                      # one value, in its last digits
    FigureStore().cached("f", draw, y2, title="one")
    FigureStore().cached("f", draw, y, title="two")    # another keyword value
    FigureStore().cached("g", draw, y, title="one")    # another figure name
    assert CALLS == ["one", "one", "two", "one"]
    assert len(list((tmp_path / "cache" / "figure").glob("*.png"))) == 4


def test_without_cache_or_fingerprint_the_figure_is_drawn(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    CALLS.clear()
    y = np.arange(5.0)
    FigureStore().cached("f", draw, y)
    FigureStore().cached("f", draw, y)
    assert CALLS == ["t", "t"]
    monkeypatch.delenv("GEARDYN_NO_CACHE")
    s = FigureStore()
    s.cached("f", draw, y, extra=object())             # cannot be fingerprinted: drawn, not cached
    assert CALLS == ["t", "t", "t"] and isinstance(s["f"], RenderedFigure)
    assert not (tmp_path / "cache" / "figure").exists()


def test_a_constrained_layout_figure_is_saved_without_a_second_tight_drawing():
    """png_bbox: a figure with a layout engine (every report figure) fits its canvas already, so
    it is saved as it is; one without is cropped to its content. The constrained figure's PNG
    is the canvas at FIGURE_DPI, its labels inside it."""
    import io

    from matplotlib.figure import Figure
    from PIL import Image

    from geardyn.studies.paper_result import FIGURE_DPI
    from geardyn.studies.report import png_bbox

    fig = Figure(figsize=(3.0, 2.0), layout="constrained")
    ax = fig.subplots()
    ax.plot([0.0, 1.0], [0.0, 1e6])
    ax.set_xlabel("a long label on the x axis [m]")
    ax.set_ylabel("y [N]")
    assert png_bbox(fig) is None
    assert png_bbox(Figure(figsize=(3.0, 2.0))) == "tight"
    assert png_bbox(RenderedFigure(b"")) == "tight"
    s = FigureStore()
    s["f"] = fig
    img = np.asarray(Image.open(io.BytesIO(s["f"].png)).convert("L"))
    assert img.shape == (2.0 * FIGURE_DPI, 3.0 * FIGURE_DPI)
    # nothing drawn on the outermost pixel rows and columns: the layout kept the labels inside
    assert img[[0, -1], :].min() == 255 and img[:, [0, -1]].min() == 255
    # ... and the labels are there: dark pixels near the bottom edge (the x label)
    assert img[-int(0.15 * FIGURE_DPI):, :].min() < 128
