"""Load-consistent FE stiffness (issue 18, item 2): the map at 60, 100 and 140 N m, secant and
tangent, against a direct FE contact solve at each load.

The paper's healthy pair on the default FE mesh (its bodies built in a temporary cache):
:class:`geardyn.stiffness.fe.FEStiffness` (influence coefficients, batched evaluation) at the
torque ``T`` against :func:`geardyn.stiffness.fe.direct.direct_contact` (the same FE bodies in
direct node-to-segment contact, no influence coefficients, no assumed pressure patch, no
analytical Hertz term) at ``dd = 0.5 mm``. Secant ``T / (dtheta r_b1^2)``; tangent by the
central difference ``2 h T / ((dtheta(T (1 + h)) - dtheta(T (1 - h))) r_b1^2)``, ``h = 0.05``,
in both. Positions in mesh angles from the pitch point: 0 (single contact), 0.5 (double
contact), -0.21 (double, pinion tip loaded near the exit) with a 1 % target, and 0.25 (the
approaching pair's gap closes under the load) reported without a target. Also the cost of the
tangent map (three evaluations) against the secant map on the paper's grid.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import time

import numpy as np

import geardyn
from _common import Row

TORQUES = (60.0, 100.0, 140.0)


def run(quick: bool = False) -> list[Row]:
    from geardyn.cache import Cache
    from geardyn.stiffness import centre_distance_grid
    from geardyn.stiffness.fe import FESettings, FEStiffness
    from geardyn.stiffness.fe.direct import direct_contact
    from geardyn.stiffness.fe.mesh import build_body_mesh
    from geardyn.stiffness.fe.model import TANGENT_STEP
    from geardyn.stiffness.fe.solve import ElasticBody
    from geardyn.stiffness.map import StiffnessMap

    case = geardyn.paper_case()
    rows: list[Row] = []
    with tempfile.TemporaryDirectory() as tmp:
        cache = Cache(os.path.join(tmp, "c"))
        base = FESettings.from_case(case)
        sec = {t: FEStiffness(case, cracked=False, cache=cache,
                              settings=dataclasses.replace(base, torque=t)) for t in TORQUES}
        tan = {t: FEStiffness(case, cracked=False, cache=cache,
                              settings=dataclasses.replace(base, torque=t, definition="tangent"))
               for t in TORQUES}
        m = sec[100.0]
        pair = m.pair
        body = ElasticBody(build_body_mesh(pair.gear, base.mesh_settings()), m.material)
        rb1, h, dd = pair.pinion.base_radius, TANGENT_STEP, 0.5e-3

        def rot(theta: float, t: float) -> float:
            return direct_contact(body, body, pair, theta, dd, t / m.face_width,
                                  reach=25e-6).rotation

        positions = ((0.0, "single"), (0.5, "double")) if quick else \
            ((0.0, "single"), (0.5, "double"), (-0.21, "double, tip"), (0.25, "gap closing"))
        for f, what in positions:
            th = f * pair.mesh_angle
            target = "" if what == "gap closing" else "within 1 %"
            for t in TORQUES:
                ks = float(sec[t].evaluate(np.array([th]), dd)["k_mb"][0])
                kt = float(tan[t].evaluate(np.array([th]), dd)["k_mb"][0])
                ds = t / rot(th, t) / rb1 ** 2
                dt = 2 * h * t / (rot(th, t * (1 + h)) - rot(th, t * (1 - h))) / rb1 ** 2
                for name, k, d in (("secant", ks, ds), ("tangent", kt, dt)):
                    err = k / d - 1
                    rows.append(Row(f"k_mb {name} at {t:g} N m, {f:+.2f} mesh angles ({what}), "
                                    f"map vs direct (relative error {100 * err:+.3f} %)", k,
                                    "N/m", "direct FE contact solve", d, target,
                                    None if not target else bool(abs(err) <= 0.01)))
        # cost of the tangent: the paper's grid, one mesh cycle per centre distance
        dds = centre_distance_grid(case)
        calls = []
        StiffnessMap.from_function(pair, dds[:1], lambda th, d: calls.append(th) or
                                   m.evaluate(th, d))
        theta = calls[0]
        times = {}
        for name, mod in (("secant", sec[100.0]), ("tangent", tan[100.0])):
            mod.evaluate(theta[:4], 0.0)
            t0 = time.perf_counter()
            for d in dds:
                mod.evaluate(theta, float(d))
            times[name] = time.perf_counter() - t0
        rows.append(Row(f"healthy map evaluation, tangent ({dds.size} dd x {theta.size} nodes, "
                        "3 evaluations)", times["tangent"], "s", "secant (1 evaluation)",
                        times["secant"], "", None))
    return rows


if __name__ == "__main__":  # python benchmarks/bench_fe_load.py [--quick]
    for row in run(quick="--quick" in sys.argv):
        base = "" if row.baseline_value is None else \
            f"; {row.baseline}: {row.baseline_value:.6g} {row.unit}"
        met = "" if row.met is None else f"; target {row.target}: {'met' if row.met else 'NOT met'}"
        print(f"{row.name}: {row.value:.6g} {row.unit}{base}{met}", flush=True)
