"""Comparisons with the paper (Xue & Howard 2018) that depend on the mesh stiffness and the
dynamics, with the PEM stiffness map: Fig. 9 iteration pattern, Table 2 magnitudes, handovers.
The consistency checks (static balance, calibrated inputs) are in test_paper_consistency.py.

Tolerances: Table 2 is compared in log-ratio, symmetric, within the report's factor 2 for every
standard deviation (geardyn.studies.paper_validation.STD_FACTOR, fixed before comparing: the
paper gives no uncertainty, and the damping, inertias and couplings it leaves unspecified scale
the response). Measured: transmission error 1.15 (model I) and 1.07 (model II), the other signals
1.2-1.9. Halving the mesh stiffness must fail the comparison (measured 2.4 and 2.3:
test_halved_mesh_stiffness_keeps_the_checks_and_fails_the_comparison)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import geardyn
from geardyn.dynamics import simulate, summary
from geardyn.studies.paper_validation import STD_FACTOR

CRACKED_TOOTH = 11                    # the case file's cracked pinion tooth

#: Table 2 of the paper: standard deviations of model I and model II.
TABLE2 = {"v_yg": (0.0100, 0.0127), "omega_p": (0.1389, 0.1815),
          "transmission_error": (2.6e-5, 3.2e-5)}
#: Allowed factor (symmetric in log-ratio) of each Table 2 comparison, see the module docstring.
TABLE2_FACTOR = {"v_yg": STD_FACTOR, "omega_p": STD_FACTOR, "transmission_error": STD_FACTOR}


@pytest.fixture(scope="module")
def runs(paper_runs):
    return paper_runs


@pytest.fixture(scope="module")
def case(paper_run_case):
    return paper_run_case


@pytest.fixture(scope="module")
def pem(paper_pem):
    return paper_pem


def table2_comparison(runs) -> dict[tuple[str, str], tuple[float, bool]]:
    """(signal, model) -> (ratio geardyn/paper, within the allowed factor)."""
    out = {}
    for name, paper in TABLE2.items():
        for w, p in zip(("I", "II"), paper, strict=True):
            r = float(runs[w][name].std()) / p
            out[(name, w)] = (r, abs(math.log(r)) < math.log(TABLE2_FACTOR[name]))
    return out


def _handover_distance_steps(ds, pem):
    """Steps from each sample to the nearest handover (zone boundary at the sample's dd)."""
    tm = pem.mesh_angle
    dd = ds.centre_distance_change.values
    a = np.interp(dd, pem.dd, pem.phase_a)
    la = np.interp(dd, pem.dd, pem.length_a)
    r = (ds.theta_p.values - a) % tm
    dist = np.minimum(np.minimum(r, tm - r), np.abs(r - la))
    return dist / (ds.omega_p.values * ds.attrs["dt"])


def _cracked_tooth_in_mesh(ds, pair):
    th = ds.theta_p.values % (2 * math.pi)
    s = pair.pitch_point_s + pair.pinion.base_radius * th - CRACKED_TOOTH * pair.base_pitch
    s_start = np.array([pair.operating(d).s_start for d in ds.centre_distance_change.values])
    return (s >= s_start) & (s <= pair.operating(0.0).s_end)


def test_model_ii_iterates_only_at_handovers_and_the_crack(runs, case, pem):
    """Fig. 9. With the second-order predictor the first-solve |b1 - b2| peaks at the tooth
    handovers and is largest while the cracked tooth is in mesh; at the paper's 0.1 um it never
    exceeds the tolerance at dt = 1e-5 s (no iterations needed). With a 10x tighter tolerance the
    iterations happen exactly at the handover steps (within one step), and nowhere else."""
    ds = runs["II"]
    rb = ds.residual_before.values
    assert rb.max() < 1e-7 and ds.iterations.values.max() == 0
    hd = _handover_distance_steps(ds, pem)
    crack = _cracked_tooth_in_mesh(ds, case.gear_pair())
    assert rb[crack].max() > 1.1 * rb[~crack].max()          # the crack gives the largest
    assert rb[hd > 20].max() < 0.25 * rb.max()               # peaks sit at the handovers
    tight = simulate(case.with_overrides({"simulation.tolerance": 1e-8}), pem, model="II")
    it = tight.iterations.values
    assert 0.002 < np.mean(it > 0) < 0.05
    assert _handover_distance_steps(tight, pem)[it > 0].max() <= 1.5
    # the tighter tolerance changes the transmission error by less than 0.1 % of its STD
    # (measured 0.06 %, 2.0e-8 rad, with the step-averaged stiffness; < 1e-8 rad point-sampled)
    te = ds.transmission_error.values
    assert np.abs(tight.transmission_error.values - te).max() < 1e-3 * np.std(te)


def test_paper_flow_chart_iterates_where_the_centre_distance_moves(case, pem):
    """The paper's scheme (stiffness at the start of the step): |b1 - b2| before iterating is
    the centre distance change over a step, 0.2-0.5 um (Fig. 9a: 0.2 um at handovers, 0.4 um at
    the crack), and iterations are more frequent in the double-contact (handover) zone."""
    ds = simulate(case.with_overrides({"simulation.stiffness_evaluation": "start"}), pem,
                  model="II")
    rb, it = ds.residual_before.values, ds.iterations.values
    assert 0.2e-6 < rb.max() < 1e-6
    assert ds.residual_after.values.max() < 1e-7
    tm = pem.mesh_angle
    dd = ds.centre_distance_change.values
    r = (ds.theta_p.values - np.interp(dd, pem.dd, pem.phase_a)) % tm
    double = r >= np.interp(dd, pem.dd, pem.length_a)
    assert np.mean(it[double] > 0) > 1.5 * np.mean(it[~double] > 0)
    crack = _cracked_tooth_in_mesh(ds, case.gear_pair())
    assert rb[crack].max() > rb[~crack].max()


def test_table2_magnitudes(runs):
    """Every Table 2 row within its factor (module docstring), and model II larger than model I
    in all three signals, as in the paper."""
    rows = table2_comparison(runs)
    assert all(ok for _, ok in rows.values()), rows
    for name in TABLE2:
        assert rows[(name, "II")][0] * TABLE2[name][1] > rows[(name, "I")][0] * TABLE2[name][0]


def test_halved_mesh_stiffness_keeps_the_checks_and_fails_the_comparison(case, pem, runs):
    """With the mesh stiffness halved, the consistency checks still pass (they are fixed by the
    static balance and the calibrated load: mean force 1542.3 N, 1.0852 mm, 114.14 rad/s) while
    the transmission error of Table 2 leaves its factor in both models (measured 2.4 and 2.3)."""
    half = dataclasses.replace(pem, k_mb=0.5 * pem.k_mb)
    soft = {w: simulate(case, half, model=w) for w in ("I", "II")}
    for w in ("I", "II"):
        s = summary(soft[w])
        assert round(s["mean_mesh_force_N"], 1) == 1542.3
        assert round(s["mean_centre_distance_change_m"] * 1e3, 4) == 1.0852
        assert s["mean_pinion_speed_rad_s"] == pytest.approx(114.14, rel=1e-4)
    rows = table2_comparison(soft)
    assert not rows[("transmission_error", "I")][1] and not rows[("transmission_error", "II")][1]
    assert rows[("transmission_error", "I")][0] > 2.0
    # the stiffer map passes (test_table2_magnitudes): the comparison separates the two
    assert table2_comparison(runs)[("transmission_error", "I")][1]


def test_handover_inside_a_step_has_no_fixed_point_and_is_accepted(pem):
    """Stiffness sampled at a point: at 170 N m and tol = 1e-8 m some steps' handover lies
    between the two centre distances
    the iteration visits (higher k moves the handover past theta, lower k moves it back): no
    fixed point exists. Those steps are accepted on the first solve's side after a detected
    two-cycle (the run used to stop with 'did not converge' at 0.243 s), they sit at handovers,
    and the kernel and its Python twin take the same decisions there."""
    from geardyn.dynamics import DynamicModel, initial_state, run_steps, static_equilibrium
    from geardyn.dynamics import _kernel as K
    from geardyn.dynamics.newmark import _setup_for_case

    c = geardyn.paper_case({"simulation.settle_time": 0.0, "simulation.record_time": 0.25,
                            "simulation.tolerance": 1e-8, "motor.torque": 170.0,
                            "simulation.stiffness_window": "point"})
    # averaged over each step's rotation (the default) the stiffness is continuous in d and
    # every step has its fixed point
    assert simulate(c.with_overrides({"simulation.stiffness_window": "step"}), pem,
                    model="II").attrs["steps_without_fixed_point"] == 0
    ds = simulate(c, pem, model="II")
    ra = ds.residual_after.values
    stuck = ra >= 1e-8
    assert ds.attrs["steps_without_fixed_point"] == int(stuck.sum()) >= 1
    assert _handover_distance_steps(ds, pem)[stuck].max() <= 1.5
    assert np.nanmax(ra) < 1e-7                          # within the paper's 0.1 um anyway
    # kernel and twin from the state just before the first such step
    n_stuck = int(np.nonzero(stuck)[0][0])
    dyn = DynamicModel.from_case(c, pem)
    static = static_equilibrium(dyn, pem, which="II")
    setup = _setup_for_case(c, dyn, pem, "II", static)
    st, ist = initial_state(setup, static.z)
    assert run_steps(setup, st, ist, n_stuck - 3)[0] == 0
    recs = []
    for python in (False, True):
        s, i = st.copy(), ist.copy()
        out = np.full((6, K.N_REC), np.nan)
        assert run_steps(setup, s, i, 5, rec_start=0, out=out, python=python)[0] == 0
        recs.append(out)
    np.testing.assert_array_equal(recs[0][:, K.R_IT], recs[1][:, K.R_IT])
    assert recs[0][:, K.R_RA].max() >= 1e-8
    np.testing.assert_allclose(recs[0][:, K.R_Z + 1], recs[1][:, K.R_Z + 1], rtol=1e-9)
