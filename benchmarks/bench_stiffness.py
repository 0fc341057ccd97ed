"""Stiffness benchmarks: a full PEM map cold, and map lookups from compiled code.

* Full map: 31 centre distances x 368 nodes per revolution (n_seg = 8: 23 cycles x 2 zones x 8),
  healthy + cracked tooth tables built from scratch. Target < 2 s. Baseline in the same run: the
  straightforward approach, every pair's energy integrals evaluated afresh with adaptive
  ``scipy.integrate.quad`` at each (theta, d), timed on a random subset of nodes and scaled to the
  full map.
* Lookups: a numba loop calling :func:`geardyn.stiffness.map.lookup` 1e7 times at varying
  (theta, d). Target > 1e7 lookups/s. Baseline: the NumPy twin ``lookup_reference``.
"""

from __future__ import annotations

import time
import warnings

import numba
import numpy as np

import geardyn
from _common import Row, best_time
from geardyn.stiffness import centre_distance_grid
from geardyn.stiffness.map import lookup, lookup_reference
from geardyn.stiffness.pem import PEMModel, SainsotRangeWarning, pem_map, tooth_compliance_quad


@numba.njit(cache=True, nogil=True, fastmath=False)
def _lookup_loop(n, period, dd_lo, dd_hi, dd0, ddd, pa, la, tm, nc, ns, vals):
    acc = 0.0
    for k in range(n):
        theta = (k * 0.000731) % period
        dd = dd_lo + (dd_hi - dd_lo) * ((k * 0.618033988749895) % 1.0)
        acc += lookup(theta, dd, dd0, ddd, pa, la, tm, nc, ns, vals)
    return acc


def _quad_node(pm: PEMModel, theta: float, dd: float) -> float:
    """k_mb at one (theta, d) with every energy integral by adaptive quad (the baseline)."""
    pair = pm.pair
    op = pair.operating(dd)
    cp = pair.contact_points(theta, dd)
    k = 0.0
    for n, s, ok in zip(cp.pair, cp.s, cp.in_contact, strict=True):
        if not ok:
            continue
        crack = pm.crack
        pc = crack is not None and crack.gear == "pinion" and n % pair.pinion.teeth == crack.tooth
        c1 = tooth_compliance_quad(pm.sections[("pinion", pc)], s / pair.pinion.base_radius,
                                   pm.E, pm.nu, pm.L, epsabs=1e-10, epsrel=1e-8)
        c2 = tooth_compliance_quad(pm.sections[("gear", False)],
                                   (op.t1t2 - s) / pair.gear.base_radius, pm.E, pm.nu, pm.L,
                                   epsabs=1e-10, epsrel=1e-8)
        k += 1.0 / (pm.hertz + c1 + c2)
    return k


def run(quick: bool = False) -> list[Row]:
    case = geardyn.paper_case().with_overrides({"stiffness.nodes_per_segment": 8})
    dd = centre_distance_grid(case)
    rows: list[Row] = []

    def full_map():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SainsotRangeWarning)
            pem_map(case, dd, cracked=False)
            return pem_map(case, dd, cracked=True)

    m = full_map()  # warm imports and numba
    nodes = m.k_mb.size
    t_map = best_time(full_map, repeat=2 if quick else 3) / 2  # per map
    # baseline: quad at a random subset of nodes, scaled
    pm = PEMModel.from_case(case, cracked=True)
    rng = np.random.default_rng(0)
    th_nodes = m.node_theta()
    n_sub = 10 if quick else 40
    picks = [(int(rng.integers(dd.size)), int(rng.integers(th_nodes.shape[1])))
             for _ in range(n_sub)]
    t0 = time.perf_counter()
    worst = 0.0
    for i, j in picks:
        kq = _quad_node(pm, float(th_nodes[i, j]), float(dd[i]))
        worst = max(worst, abs(kq / m.k_mb[i, j] - 1))
    t_quad = (time.perf_counter() - t0) / n_sub * nodes
    rows.append(Row(f"PEM map {dd.size} x {th_nodes.shape[1]} nodes/rev, cold (tables + map; "
                    f"max dev. from quad {worst:.1e})", t_map, "s",
                    "quad at every node (subset, scaled)", t_quad, "< 2 s", t_map < 2.0))

    # lookups from compiled code
    arr = m.arrays()
    n = 2_000_000 if quick else 10_000_000
    args = (m.period, float(dd[0]), float(dd[-1]), *arr)
    _lookup_loop(1000, *args)  # compile
    t = best_time(lambda: _lookup_loop(n, *args), repeat=3)
    rate = n / t
    n_ref = 5_000 if quick else 20_000
    th = (np.arange(n_ref) * 0.000731) % m.period
    dq = dd[0] + (dd[-1] - dd[0]) * ((np.arange(n_ref) * 0.618033988749895) % 1.0)
    t_ref = best_time(lambda: lookup_reference(th, dq, arr), repeat=1)
    rows.append(Row(f"map lookups from a numba loop ({n:.0e})", rate, "lookups/s",
                    "NumPy twin lookup_reference", n_ref / t_ref, "> 1e7 /s", rate > 1e7))
    return rows


if __name__ == "__main__":
    for r in run(quick=False):
        print(r, f"ratio {r.ratio:.3g}" if r.ratio else "")
