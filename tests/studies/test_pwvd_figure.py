"""The report's PWVD figures (Figs. 14/15/18/21 analogues) pick each pixel's cell before colouring
it (``interpolation_stage="data"``, less work): the pixels must be those of colouring every cell
first and then picking (matplotlib's own choice when it shrinks an image). Oracle: the same
figure drawn with ``interpolation_stage="rgba"`` forced. The two orders pick the same cell and
colour it with the same colour map, but scale it to the map's 256 colours at different points
(matplotlib 3.8: 4 of 2.4 million values differ; 3.11: none), so a value at the edge between
two colours may get the neighbouring one: every pixel that differs must be one colour-map step
from the other's, and only pixels of the image may differ."""

from __future__ import annotations

import io
from types import SimpleNamespace

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from PIL import Image

from geardyn.studies import paper_figures as pf
from geardyn.studies.paper_result import render_png


def _diags() -> dict:
    """Two models' diagnoses of ``v_yg`` with a PWVD-like distribution: 2048 angles x orders
    0-200 in steps of 0.5, a mesh-order ridge, a fault burst and small negative interference."""
    angle = np.linspace(0.0, 2 * np.pi, 2048, endpoint=False)
    orders = np.arange(0.0, 200.5, 0.5)
    rng = np.random.default_rng(3)
    out = {}
    for m, burst in (("I", 1.0), ("II", 3.0)):
        d = (np.exp(-((orders[None, :] - 23.0) / 1.5) ** 2)
             + burst * np.exp(-((angle[:, None] - 3.0) / 0.05) ** 2 - (orders[None, :] / 60.0) ** 2)
             + 0.05 * rng.standard_normal((angle.size, orders.size)))
        pw = SimpleNamespace(distribution=d, orders=orders, angle=angle)
        out[m] = SimpleNamespace(signals={"v_yg": SimpleNamespace(pwvd_tsa=pw, pwvd_residual=pw)})
    return out


def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)))


def test_pwvd_figure_pixels_equal_colouring_every_cell_first(monkeypatch):
    fast = _pixels(render_png(pf.fig_pwvd_pair(_diags(), "v_yg", "tsa", 23, 140.0)))
    imshow = Axes.imshow

    def rgba_stage(self, *args, **kwargs):
        assert kwargs.get("interpolation_stage") == "data"  # what the figure asks for
        kwargs["interpolation_stage"] = "rgba"
        return imshow(self, *args, **kwargs)

    monkeypatch.setattr(Axes, "imshow", rgba_stage)
    reference = _pixels(render_png(pf.fig_pwvd_pair(_diags(), "v_yg", "tsa", 23, 140.0)))
    assert fast.shape == reference.shape and fast.shape[0] > 300
    differ = np.any(fast != reference, axis=-1)
    assert differ.mean() < 1e-3, differ.sum()  # rounding at a colour's edge only
    lut = np.round(matplotlib.colormaps["viridis"](np.arange(256))[:, :3] * 255)

    def colour_index(rgba: np.ndarray) -> np.ndarray:
        dist = np.abs(rgba[:, None, :3].astype(float) - lut[None, :, :]).max(axis=-1)
        assert (dist.min(axis=1) <= 1).all(), "a pixel that differs is not a colour of the map"
        return dist.argmin(axis=1)

    steps = np.abs(colour_index(fast[differ]) - colour_index(reference[differ]))
    assert (steps <= 1).all(), steps.max()
    # the images are not trivial: the ridge and the burst span many colours
    assert len(np.unique(fast.reshape(-1, fast.shape[-1]), axis=0)) > 100
