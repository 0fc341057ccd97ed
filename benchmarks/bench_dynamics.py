"""Dynamics benchmark: time steps per second of model I and model II on the paper case.

Rows (all measured in this run):

* the numba kernel against the same algorithm as a plain Python/NumPy loop (the kernel's twin,
  ``geardyn.dynamics._kernel.advance_python``), paper case with the PEM map (cracked), recording
  every step; target: model II at or under 0.3 us per step;
* ``simulate()`` end to end for the default 1.5 s (0.5 s settling + 1 s record);
* the kernel against scipy's DOP853 with a numba-compiled right-hand side of eqs. 9-16 at matched
  accuracy: the DOP853 ``rtol`` is loosened until its transmission error (against DOP853 at rtol
  1e-12) is no better than Newmark's at dt = 1e-5 s. This comparison uses a map that is continuous
  in theta (linear in each contact zone): with the PEM map's handover steps DOP853 would need
  event location at every handover to be accurate at all.

Run: ``python benchmarks/run.py dynamics`` (``--quick`` for a smoke test).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from _common import Row, best_time

ROOT = Path(__file__).resolve().parents[1]


def _paper_setup(which: str, case, smap):
    from geardyn.dynamics import DynamicModel, static_equilibrium
    from geardyn.dynamics.newmark import _setup_for_case

    dyn = DynamicModel.from_case(case, smap)
    static = static_equilibrium(dyn, smap, which=which)
    return _setup_for_case(case, dyn, smap, which, static), static


def _steps_per_second(setup, static, n: int, python: bool, repeat: int) -> float:
    from geardyn.dynamics import _kernel as K
    from geardyn.dynamics import initial_state, run_steps

    out = np.empty((n + 1, K.N_REC))

    def go():
        st, ist = initial_state(setup, static.z)
        status, _, _ = run_steps(setup, st, ist, n, out=out, python=python)
        assert status == 0

    if not python:
        go()  # compile / warm up
    return n / best_time(go, repeat=repeat)


def run(quick: bool) -> list[Row]:
    sys.path.insert(0, str(ROOT))
    import geardyn
    from geardyn.dynamics import simulate
    from geardyn.stiffness import centre_distance_grid
    from geardyn.stiffness.pem import pem_map

    rows: list[Row] = []
    case = geardyn.paper_case()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        smap = pem_map(case, centre_distance_grid(case), cracked=True)
    n_kernel = 20_000 if quick else 200_000
    n_numpy = 300 if quick else 2_000
    rate = {}
    for which in ("I", "II"):
        setup, static = _paper_setup(which, case, smap)
        fast = _steps_per_second(setup, static, n_kernel, False, repeat=3 if quick else 5)
        slow = _steps_per_second(setup, static, n_numpy, True, repeat=1)
        rate[which] = fast
        target = "(see the us/step row)" if which == "II" else ""
        rows.append(Row(f"model {which} Newmark kernel, paper case (PEM, cracked)", fast,
                        "steps/s", "same algorithm, plain NumPy loop", slow, target, None))
    us = 1e6 / rate["II"]
    rows.append(Row("model II time per step (recording every step)", us, "us/step",
                    "model I kernel", 1e6 / rate["I"], "<= 0.3 us/step", us <= 0.3))

    # ---- end to end
    c = case if not quick else case.with_overrides({"simulation.settle_time": 0.05,
                                                    "simulation.record_time": 0.1})
    simulate(c.with_overrides({"simulation.record_time": 0.001, "simulation.settle_time": 0}),
             smap, model="II")
    t_e2e = best_time(lambda: simulate(c, smap, model="II"), repeat=1 if quick else 3)
    n_steps = round((c.simulation.settle_time + c.simulation.record_time) / c.simulation.dt)
    rows.append(Row(f"simulate() model II end to end, {n_steps} steps incl. Dataset", t_e2e, "s",
                    "", None, "", None))

    # ---- DOP853 at matched accuracy (smooth map, model II)
    rows.extend(_dop853_rows(quick))
    return rows


def _dop853_rows(quick: bool) -> list[Row]:
    from scipy.integrate import solve_ivp
    from tests.dynamics._support import _rhs, dop853_reference, short_case, triangle_map

    from geardyn.dynamics import simulate

    t_end = 0.02 if quick else 0.05
    names = ("theta_m", "y_p", "theta_p", "y_g", "theta_g", "theta_out",
             "omega_m", "v_yp", "omega_p", "v_yg", "omega_g", "omega_out")
    out = []
    for which in ("I", "II"):
        case = short_case(**{"simulation.record_time": t_end + 1e-5})
        smap = triangle_map(case.gear_pair())
        ds = simulate(case, smap, model=which)
        setup, static = _paper_setup(which, case, smap)
        rate_new = _steps_per_second(setup, static, int(round(t_end / 1e-5)), False, repeat=5)
        y0 = np.array([ds[v].values[0] for v in names])
        t_eval = ds.time.values[::10]
        ref = dop853_reference(case, smap, which, y0, t_eval, rtol=1e-12)
        te_ref = ref[2] - ref[4]
        err_newmark = np.abs(ds.transmission_error.values[::10] - te_ref).max()
        # the RHS as the reference uses it
        from geardyn.dynamics import DynamicModel

        dyn = DynamicModel.from_case(case, smap)
        q, pair = dyn.damping, dyn.pair
        par = (dyn.M[0, 0], dyn.M[1, 1], dyn.M[2, 2], dyn.M[3, 3], dyn.M[4, 4], dyn.M[5, 5],
               -dyn.K0[0, 2], -dyn.K0[4, 5], dyn.K0[1, 1], dyn.K0[3, 3], q["q_cp"], q["q_cg"],
               q["q_yp"], q["q_yg"], q["q_stp"], q["q_stg"], dyn.q_mb, dyn.r_b1, dyn.r_b2,
               pair.base_radius_sum, pair.design_t1t2, pair.design_centre_distance,
               dyn.input_law.coefficient, dyn.output_law.coefficient)
        arr = smap.arrays()
        m2 = which == "II"

        def f(t, y, par=par, m2=m2, arr=arr):
            return _rhs(y, par, m2, *arr)

        chosen = None
        for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11):
            sol = solve_ivp(f, (0.0, float(t_eval[-1])), y0, method="DOP853", rtol=rtol,
                            atol=rtol * 1e-3, t_eval=t_eval)
            err = np.abs(sol.y[2] - sol.y[4] - te_ref).max()
            if sol.success and err <= err_newmark:
                chosen = (rtol, err)
                break
        assert chosen is not None
        rtol = chosen[0]
        t_dop = best_time(lambda rtol=rtol, f=f, y0=y0, te=t_eval: solve_ivp(
            f, (0.0, float(te[-1])), y0, method="DOP853", rtol=rtol, atol=rtol * 1e-3,
            t_eval=te), repeat=3)
        n = t_end / 1e-5
        out.append(Row(f"model {which} kernel vs DOP853 at matched TE error "
                       f"(Newmark {err_newmark:.2g} rad, DOP853 {chosen[1]:.2g} rad at rtol "
                       f"{rtol:.0e}), {t_end * 1e3:g} ms, "
                       "continuous map", rate_new, "steps/s",
                       "scipy DOP853, numba RHS (per 1e-5 s simulated)", n / t_dop, "", None))
    return out


if __name__ == "__main__":  # pragma: no cover
    for r in run(quick="--quick" in sys.argv):
        print(r, f"ratio {r.ratio:.3g}" if r.ratio else "")
