"""The report's PWVD figures (Figs. 14/15/18/21 analogues) pick each pixel's cell before colouring
it (``interpolation_stage="data"``, less work): the pixels must be those of colouring every cell
first and then picking (matplotlib's own choice when it shrinks an image). Oracle: the same
figure drawn with ``interpolation_stage="rgba"`` forced."""

from __future__ import annotations

import io
from types import SimpleNamespace

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
    np.testing.assert_array_equal(fast, reference)
    # the images are not trivial: the ridge and the burst span many colours
    assert len(np.unique(fast.reshape(-1, fast.shape[-1]), axis=0)) > 100
