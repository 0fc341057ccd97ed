"""K(theta, d, F) (issue 18.2): the 6-DOF kernel reading maps at several mesh loads, linear in
each step's elastic mesh force."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.dynamics import DynamicModel, simulate
from geardyn.dynamics.model import static_equilibrium
from geardyn.dynamics.newmark import _setup_for_case, initial_state, run_steps
from geardyn.errors import InputError
from geardyn.stiffness import LoadFamily, StiffnessMap

from ._support import constant_map, short_case, triangle_map


def _scaled(smap: StiffnessMap, factor: float) -> StiffnessMap:
    """The map with every node value times ``factor``."""
    return StiffnessMap(**{**smap.__dict__, "k_mb": np.asarray(smap.k_mb) * factor})


def _family(pair, base, factors, torques):
    return LoadFamily(torques, [_scaled(base, f) for f in factors], pair.pinion.base_radius)


def _run(case, smap, family, which="II", python=False, steps=400):
    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which=which)
    setup = _setup_for_case(case, dyn, smap, which, static, family)
    st, ist = initial_state(setup, static.z)
    from geardyn.dynamics import _kernel as K

    out = np.full((steps + 1, K.N_REC), np.nan)
    status, j, _ = run_steps(setup, st, ist, steps, out=out, python=python)
    assert status == 0
    return out[:j]


def test_a_family_of_equal_maps_is_the_single_map():
    """Three identical maps at 60, 100, 140 N m: the records of the single map to 1e-12."""
    case = short_case()
    pair = case.gear_pair()
    base = triangle_map(pair)
    fam = _family(pair, base, (1.0, 1.0, 1.0), (60.0, 100.0, 140.0))
    a = _run(case, base, None)
    b = _run(case, base, fam)
    scale = np.abs(a).max(axis=0)
    scale[scale == 0] = 1.0
    assert np.nanmax(np.abs(a - b) / scale) < 1e-12


@pytest.mark.parametrize("which", ["I", "II"])
def test_kernel_equals_its_twin_with_a_load_family(which):
    """Maps scaled 0.9 / 1.0 / 1.15 at 60 / 100 / 140 N m (nonlinear in the load), 400 steps:
    the compiled kernel and the NumPy twin to 1e-9 of each column's peak, and the family
    changes the record (so the comparison is not of two single-map runs)."""
    case = short_case(**{"simulation.rtol": 1e-12, "simulation.tolerance": 1e-13})
    pair = case.gear_pair()
    base = triangle_map(pair)
    fam = _family(pair, base, (0.9, 1.0, 1.15), (60.0, 100.0, 140.0))
    from geardyn.dynamics import _kernel as K

    a = _run(case, base, fam, which)
    b = _run(case, base, fam, which, python=True)
    c = _run(case, base, None, which)
    cols = list(range(K.R_Z, K.R_V + 6)) + [K.R_N, K.R_DD, K.R_K]  # not the iteration counts:
    scale = np.abs(a[:, cols]).max(axis=0)                           # the kernel solves the
    scale[scale == 0] = 1.0                                          # load by secant steps
    assert np.nanmax(np.abs(a[:, cols] - b[:, cols]) / scale) < 1e-9

    assert np.abs(a[:, K.R_K] - c[:, K.R_K]).max() > 1e-4 * np.abs(c[:, K.R_K]).max()


def test_static_deflection_follows_the_load_dependent_stiffness():
    """Constant maps k0 (1 + beta (F - F0)/F0) at three loads (linear in F): after the
    start-up transient has died away the mesh deflection is N / k(N) (closed form: the secant
    stiffness at the record's own mesh force), not N / k0."""
    case = short_case(**{"simulation.settle_time": 0.3, "simulation.record_time": 0.01,
                         "simulation.rtol": 1e-12, "motor.torque": 120.0})
    pair = case.gear_pair()
    rb1 = pair.pinion.base_radius
    k0, beta = 1.2e8, 0.4
    torques = (60.0, 100.0, 140.0)
    f0 = 100.0 / rb1
    maps = [constant_map(pair, k0 * (1 + beta * (t / rb1 - f0) / f0)) for t in torques]
    fam = LoadFamily(torques, maps, rb1)
    dyn = DynamicModel.from_case(case, maps[1])
    static = static_equilibrium(dyn, maps[1], which="I")
    setup = _setup_for_case(case, dyn, maps[1], "I", static, fam)
    st, ist = initial_state(setup, static.z)
    from geardyn.dynamics import _kernel as K

    n = int(0.3 / case.simulation.dt)
    out = np.full((1, K.N_REC), np.nan)
    status, j, _ = run_steps(setup, st, ist, n, rec_start=n - 1, out=out)
    assert status == 0 and j == 1
    N = st[K.S_N]
    p = float(setup.g @ st[K.S_Z:K.S_Z + 6])
    k_closed = k0 * (1 + beta * (N - f0) / f0)
    assert p == pytest.approx(N / k_closed, rel=1e-7)
    assert abs(N / k0 - p) > 1e-3 * p        # the load dependence is visible
    assert st[K.S_K] == pytest.approx(k_closed, rel=1e-9)


def test_the_case_field_and_its_refusals():
    """``stiffness.fe.torques``: at least two increasing torques, bracketing the operating
    torque; PEM ignores it (its map does not depend on the load); the transverse model
    refuses it."""
    from geardyn.stiffness import build_load_family

    case = short_case()
    with pytest.raises(Exception, match="increasing"):
        case.with_overrides({"stiffness.fe.torques": [100.0, 80.0]})
    with pytest.raises(Exception, match="at least two"):
        case.with_overrides({"stiffness.fe.torques": [100.0]})
    assert build_load_family(case.with_overrides({"stiffness.fe.torques": [80.0, 120.0]})) \
        is None  # PEM
    fe = case.with_overrides({"stiffness.method": "fe", "stiffness.fe.torques": [110.0, 120.0]})
    with pytest.raises(InputError, match="bracketing the operating torque 100"):
        build_load_family(fe)
    tangent = case.with_overrides({"stiffness.method": "fe", "stiffness.fe.torques": [80.0, 120.0],
                                   "stiffness.fe.definition": "tangent"})
    with pytest.raises(InputError, match="secant"):
        build_load_family(tangent)
    tr = case.with_overrides({"stiffness.method": "fe", "stiffness.fe.torques": [80.0, 120.0],
                              "simulation.dynamics": "transverse"})
    with pytest.raises(InputError, match="stiffness.fe.torques"):
        simulate(tr, triangle_map(case.gear_pair()))


@pytest.mark.slow
def test_with_a_load_family_the_scheme_keeps_order_two():
    """Self-convergence with the family of the twin test: the differences to a run at
    dt = 1.25 us are C (dt^2 - 1.25 us^2) with one C (within 10 %) for dt = 10, 5, 2.5 us."""
    case = short_case(**{"simulation.rtol": 1e-12, "simulation.tolerance": 1e-13})
    pair = case.gear_pair()
    base = triangle_map(pair)
    fam = _family(pair, base, (0.9, 1.0, 1.15), (60.0, 100.0, 140.0))
    from geardyn.dynamics import _kernel as K

    t_end = 0.01
    ref = None
    res = {}
    for dt in (1.25e-6, 2.5e-6, 5e-6, 1e-5):
        c = case.with_overrides({"simulation.dt": dt})
        rows = _run(c, base, fam, "II", steps=int(round(t_end / dt)))
        te = rows[:, K.R_Z + 2] - pair.gear.base_radius / pair.pinion.base_radius \
            * rows[:, K.R_Z + 4]
        stride = int(round(1e-5 / dt))
        res[dt] = te[::stride]
    ref = res[1.25e-6]
    dts = (1e-5, 5e-6, 2.5e-6)
    errs = np.array([np.abs(res[dt] - ref).max() for dt in dts])
    # error C dt^2 in each run: the difference to the finest is C (dt^2 - dt_f^2)
    expected = np.array([dt ** 2 - 1.25e-6 ** 2 for dt in dts])
    ratio = errs / expected
    assert np.all(np.abs(ratio / ratio[0] - 1.0) < 0.1), (errs, ratio)
