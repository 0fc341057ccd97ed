"""The PWVD computed a block of angles at a time (memory, issue 16) equals the whole-array
computation bit for bit, for every branch (periodic or not, smoothed or not, order cut)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.diagnostics import tfd


@pytest.mark.parametrize("kw", [{}, {"max_order": 300.0}, {"periodic": False},
                                {"time_window_length": 11},
                                {"time_window_length": 11, "periodic": False, "max_order": 200.0},
                                {"n_fbins": 1024, "window_length": 101}])
def test_blocks_equal_one_block(monkeypatch, kw):
    x = np.random.default_rng(3).normal(size=1500)
    blocked = tfd.pwvd(x, **kw).distribution
    monkeypatch.setattr(tfd, "_PWVD_ROWS", 10 ** 9)  # one block: the whole spectrum at once
    whole = tfd.pwvd(x, **kw).distribution
    assert blocked.shape == whole.shape
    assert np.array_equal(blocked, whole)
