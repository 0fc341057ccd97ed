"""The stiffness averaged over each time step's rotation (``simulation.stiffness_window``).

A contact handover is a step of ``K(theta)``. Sampled at one angle per time step it takes effect
at the next step boundary, a timing error of up to one step that changes from one mesh cycle to
the next (the step is not commensurate with the mesh period): not periodic with the mesh, it
survives the TSA and shows in a healthy gear's residual, the signal every condition indicator
is computed from. :func:`geardyn.stiffness.map.lookup_box` averages the map over the step's
rotation instead. Oracles: a dense quadrature of the point map over the window, the NumPy twin,
and the TSA residual of a perfect gear, which is zero for the exact (continuous-time) periodic
response and so measures the integration error alone.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import trapezoid

import geardyn
from geardyn.stiffness import build_map
from geardyn.stiffness.map import lookup, lookup_box, lookup_box_reference


@pytest.fixture(scope="module")
def healthy():
    case = geardyn.paper_case({"stiffness.method": "pem", "crack.enabled": False,
                               "stiffness.centre_distances": 6})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return case, build_map(case, cracked=False)


def _args(arr):
    return (arr.dd0, arr.ddd, arr.phase_a, arr.length_a, arr.mesh_angle, arr.n_cycles,
            arr.n_seg, arr.values)


def _handovers(arr, dd):
    a = np.interp(dd, arr.dd0 + arr.ddd * np.arange(arr.values.shape[0]), arr.phase_a)
    la = np.interp(dd, arr.dd0 + arr.ddd * np.arange(arr.values.shape[0]), arr.length_a)
    k = np.arange(-1, arr.n_cycles + 1)
    return np.sort(np.concatenate([a + k * arr.mesh_angle, a + la + k * arr.mesh_angle]))


def test_window_average_equals_a_dense_quadrature_of_the_point_map(healthy):
    """Windows straddling each handover of one revolution, at a grid line and between two:
    the average equals a 20,001-point trapezoid of :func:`lookup` over the window to 1e-4
    relative (the trapezoid's error at the step is half a sub-interval, 5e-5 of the window)."""
    _, m = healthy
    arr = m.arrays()
    h = 5.7e-4  # half the rotation of a 10 us step at 114 rad/s [rad]
    rng = np.random.default_rng(1)
    for dd in (arr.dd0 + arr.ddd, arr.dd0 + 2.37 * arr.ddd):
        for tb in _handovers(arr, dd):
            theta = tb + rng.uniform(-0.95, 0.95) * h
            x = np.linspace(theta - h, theta + h, 20001)
            y = np.array([lookup(v, dd, *_args(arr)) for v in x])
            dense = trapezoid(y, x) / (2 * h)
            got = lookup_box(theta, h, dd, *_args(arr))
            assert got == pytest.approx(dense, rel=1e-4), (dd, tb)
            # and the average lies between the one-sided values
            lo, hi = lookup(tb - 1e-9, dd, *_args(arr)), lookup(tb + 1e-9, dd, *_args(arr))
            assert min(lo, hi) <= got <= max(lo, hi)


def test_window_without_a_handover_is_the_point_value_bit_for_bit(healthy):
    _, m = healthy
    arr = m.arrays()
    dd = arr.dd0 + 1.5 * arr.ddd
    hb = _handovers(arr, dd)
    h = 5.7e-4
    theta = np.linspace(0.0, 2 * np.pi, 5003)
    far = np.min(np.abs(theta[:, None] - hb[None, :]), axis=1) > 2 * h
    assert far.sum() > 4000
    for th in theta[far]:
        assert lookup_box(th, h, dd, *_args(arr)) == lookup(th, dd, *_args(arr))
    # a zero window is the point map everywhere
    for th in theta[::50]:
        assert lookup_box(th, 0.0, dd, *_args(arr)) == lookup(th, dd, *_args(arr))


def test_compiled_and_numpy_twin_agree(healthy):
    _, m = healthy
    arr = m.arrays()
    rng = np.random.default_rng(7)
    h = 5.7e-4
    for _ in range(300):
        dd = rng.uniform(arr.dd0, arr.dd0 + (arr.values.shape[0] - 1) * arr.ddd)
        hb = _handovers(arr, dd)
        th = rng.choice(hb) + rng.uniform(-1.5, 1.5) * h
        a = lookup_box(th, h, dd, *_args(arr))
        b = lookup_box_reference(th, h, dd, arr)
        assert a == pytest.approx(b, rel=1e-12, abs=0.0)
    assert np.isnan(lookup_box(0.1, h, arr.dd0 - arr.ddd, *_args(arr)))


def test_healthy_residual_is_integration_error_and_the_window_removes_most_of_it(healthy):
    """Paper case, perfect gears, model I (the map at a fixed d: no centre-distance dynamics),
    0.25 s recorded. The TSA residual of a perfect gear is zero for the exact periodic response.

    Point-sampled it falls in proportion to the step (first order: the handover-timing jitter;
    measured 1.6 % of the TSA's STD at 10 us, 3.1 % at 20 us, as in the 1 s runs of
    docs/verification/dynamics.md); averaged over each step it is at least ten times smaller at
    either step (measured 0.07 % at 10 us)."""
    from geardyn.diagnostics import residual, tsa
    from geardyn.dynamics import simulate

    case, m = healthy
    out = {}
    for window in ("point", "step"):
        for dt in (2e-5, 1e-5):
            c = case.with_overrides({"simulation.stiffness_window": window,
                                     "simulation.dt": dt, "simulation.record_time": 0.25})
            ds = simulate(c, m, model="I")
            avg = tsa(ds.v_yg.values, angle=ds.theta_p.values, samples_per_rev=2048).average
            out[window, dt] = np.std(residual(avg, teeth=23, preset="paper")) / np.std(avg)
    ratio = out["point", 2e-5] / out["point", 1e-5]
    assert 1.6 < ratio < 2.5, out           # first order in the step
    for dt in (2e-5, 1e-5):
        assert out["step", dt] < 0.1 * out["point", dt], out
