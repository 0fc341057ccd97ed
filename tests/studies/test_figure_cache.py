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
    s.cached("g", draw, y, title="keyword", extra=object())   # its keywords count (mutation test)
    from geardyn.studies.paper_result import render_png

    assert s["g"].png == render_png(draw(y, title="keyword"))
    assert not (tmp_path / "cache" / "figure").exists()


def test_a_title_wider_than_its_axes_is_saved_whole():
    """A constrained-layout figure (every report figure) whose right-hand title is wider than
    its axes, as the demodulation figures' are: the PNG holds the whole title (the tight box
    grows past the canvas) and nothing touches its outermost pixels. Saved as the canvas, the
    title's end was cut off."""
    import io

    from matplotlib.figure import Figure
    from PIL import Image

    from geardyn.studies.paper_result import FIGURE_DPI
    from geardyn.studies.report import png_bbox

    fig = Figure(figsize=(4.0, 2.0), layout="constrained")
    axs = fig.subplots(1, 2)
    for ax in axs:
        ax.plot([0.0, 1.0], [0.0, 1e6])
        ax.set_xlabel("a label on the x axis [m]")
    axs[1].set_title("model II: a title much longer than its axes (kurtosis 15.07)")
    assert png_bbox(fig) == "tight"
    s = FigureStore()
    s["f"] = fig
    img = np.asarray(Image.open(io.BytesIO(s["f"].png)).convert("L"))
    assert img.shape[1] > 4.0 * FIGURE_DPI           # wider than the canvas: the title's end
    assert img[[0, -1], :].min() == 255 and img[:, [0, -1]].min() == 255
    # ... and the labels are there: dark pixels near the bottom edge (the x label)
    assert img[-int(0.15 * FIGURE_DPI):, :].min() < 128
